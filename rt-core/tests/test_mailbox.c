/* Mailbox round trips between processes. */
#include <errno.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#include "arflex/mailbox.h"
#include "helper.h"

#define ROUNDS 2000

static char rid[64];

/* Child: the RT side. Replies to each request; for seq % 100 == 7 it first sends a stale
 * reply (seq - 1) that the caller must discard. Stops on SHUTDOWN. */
static int echo_server(void)
{
	struct arflex_mailbox mb;
	struct arflex_msg m;
	int r = arflex_mailbox_attach(&mb, rid, "svc");

	if (r)
		return 10;
	for (;;) {
		r = arflex_mailbox_recv(&mb, &m, 5000000000u);
		if (r)
			return 11;
		m.flags = ARFLEX_MSG_REPLY;
		m.status = (m.cmd == ARFLEX_CMD_PING || m.cmd == ARFLEX_CMD_SHUTDOWN) ? 0 : -ENOSYS;
		m.u.param.value = m.u.param.value * 2;
		if (m.seq % 100 == 7) {
			struct arflex_msg stale = m;

			stale.seq--;
			if (arflex_mailbox_send(&mb, &stale, 1000000000u))
				return 12;
		}
		if (arflex_mailbox_send(&mb, &m, 1000000000u))
			return 13;
		if (m.cmd == ARFLEX_CMD_SHUTDOWN)
			break;
	}
	arflex_mailbox_deinit(&mb);
	return 0;
}

static void round_trips(void **state)
{
	struct arflex_mailbox mb, dup;
	struct arflex_msg req, rsp;
	pid_t pid;
	int st;

	(void)state;
	th_rid(rid, sizeof(rid), "mb");
	th_track(rid, "svc");
	th_track(rid, "other");
	assert_int_equal(arflex_mailbox_create(&mb, rid, "svc"), 0);
	assert_int_equal(arflex_mailbox_create(&dup, rid, "svc"), -EEXIST);
	assert_int_equal(arflex_mailbox_create(&dup, "Bad", "svc"), -EINVAL);
	/* the RT side never creates */
	assert_int_equal(arflex_mailbox_attach(&dup, rid, "other"), -ENOENT);

	pid = fork();
	if (pid == 0)
		_exit(echo_server());
	for (uint32_t i = 1; i <= ROUNDS; i++) {
		arflex_msg_init(&req, ARFLEX_CMD_PING, i);
		req.u.param.value = i;
		assert_int_equal(arflex_mailbox_call(&mb, &req, &rsp, 5000000000u), 0);
		assert_int_equal(rsp.seq, i);
		assert_int_equal(rsp.u.param.value, 2 * i);
	}
	arflex_msg_init(&req, 99, ROUNDS + 1);
	assert_int_equal(arflex_mailbox_call(&mb, &req, &rsp, 5000000000u), -ENOSYS);
	arflex_msg_init(&req, ARFLEX_CMD_SHUTDOWN, ROUNDS + 2);
	assert_int_equal(arflex_mailbox_call(&mb, &req, &rsp, 5000000000u), 0);
	assert_int_equal(waitpid(pid, &st, 0), pid);
	assert_true(WIFEXITED(st));
	assert_int_equal(WEXITSTATUS(st), 0);

	/* no server: the call times out */
	arflex_msg_init(&req, ARFLEX_CMD_PING, 1);
	assert_int_equal(arflex_mailbox_call(&mb, &req, &rsp, 20000000u), -ETIMEDOUT);
	arflex_mailbox_deinit(&mb);
	th_assert_clean(rid);
}

static void malformed_messages_rejected(void **state)
{
	struct arflex_msg m;

	(void)state;
	arflex_msg_init(&m, ARFLEX_CMD_PING, 1);
	assert_int_equal(arflex_msg_check(&m, sizeof(m)), 0);
	assert_int_equal(arflex_msg_check(&m, 100), -EPROTO);
	m.abi_major = 2;
	assert_int_equal(arflex_msg_check(&m, sizeof(m)), -EPROTO);
	arflex_msg_init(&m, ARFLEX_CMD_PING, 1);
	m.magic = 0;
	assert_int_equal(arflex_msg_check(&m, sizeof(m)), -EPROTO);
	assert_string_equal(arflex_cmd_name(ARFLEX_CMD_BIND), "BIND");
	assert_string_equal(arflex_cmd_name(1000), "?");
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(round_trips),
		cmocka_unit_test(malformed_messages_rejected),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
