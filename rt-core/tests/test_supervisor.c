/* The supervisor's death (issue 15 finding 2, ABI.md 6.2, D10): the probe RT half in a real
 * child process whose supervisor pipe and output pipe the test holds and drops. */
#include <errno.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <fcntl.h>
#include <mqueue.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#include "arflex/host.h"
#include "helper.h"
#include "probe_kit.h"

/* Waits (with a deadline) until every bit of @bits is set in the control block's flags. */
static bool wait_flags(struct arflex_host *h, uint32_t bits, uint64_t timeout_ns)
{
	uint64_t deadline = arflex_sys_now_ns() + timeout_ns;

	while (arflex_sys_now_ns() < deadline) {
		if ((arflex_ctl_flags(h->ctl) & bits) == bits)
			return true;
		arflex_sys_sleep_until(arflex_sys_now_ns() + 200000);
	}
	fprintf(stderr, "wait_flags expired: flags 0x%x, want 0x%x\n", arflex_ctl_flags(h->ctl),
		bits);
	return false;
}

/* Issue 15, finding 2: the supervisor dies (its end of the stdin pipe closes, and nobody reads
 * the half's output any more). The half goes safe within a cycle, does not die of SIGPIPE when
 * it says so, holds for the contract's orphan hold, then exits 0 and removes its objects. */
static void supervisor_lost_holds_then_leaves_nothing(void **state)
{
	const uint64_t hold = 1000 * 1000000ull;
	struct arflex_host h;
	struct probe_out o;
	uint64_t t_drop, t_exit;
	char log[256];

	(void)state;
	setup_ids("orphan");
	probe_hold = hold;
	assert_int_equal(probe_host(&h, "arm", 0, ARFLEX_CFG_MOVES_HARDWARE, true), 0);
	probe_hold = 0;
	assert_int_equal(arflex_host_spawn_ex(&h, ARFLEX_PROBE_EXE, NULL, envp,
					      ARFLEX_HOST_SUPERVISOR_PIPE |
					      ARFLEX_HOST_OUTPUT_PIPE), 0);
	assert_int_equal(arflex_host_wait_state(&h, ARFLEX_STATE_READY, 10 * SEC), 0);
	assert_true(h.ctl->config.cfg_flags & ARFLEX_CFG_SUPERVISOR_PIPE);
	assert_int_equal(arflex_host_start(&h, T_CALL), 0);
	assert_true(wait_out(&h, updates_above, 5, false));
	assert_false(arflex_ctl_flags(h.ctl) & ARFLEX_FLAG_SAFE_ACTIVE);

	/* kill -9 of the supervisor, as the half sees it */
	arflex_host_close_output(&h);
	t_drop = arflex_sys_now_ns();
	arflex_host_drop_supervisor(&h);
	assert_true(wait_flags(&h, ARFLEX_FLAG_SUPERVISOR_LOST | ARFLEX_FLAG_SAFE_ACTIVE |
				   ARFLEX_FLAG_RESET_REQUIRED, 2 * SEC));
	/* it holds: alive, calling its safe hook, no update */
	assert_true(read_out(&h, &o));
	assert_true(wait_out(&h, safe_above, o.safe_calls + 10, false));
	assert_true(arflex_sys_now_ns() - t_drop < hold); /* else the machine is too slow */
	assert_int_equal(arflex_host_wait_exit(&h, 0), -ETIMEDOUT);
	assert_int_equal(arflex_host_reset(&h, T_CALL), -EAGAIN); /* no reset for an orphan */
	/* then it leaves, cleanly, after the hold */
	assert_int_equal(arflex_host_wait_exit(&h, 10 * SEC), 0);
	t_exit = arflex_sys_now_ns();
	assert_true(t_exit - t_drop >= hold);
	assert_true(WIFEXITED(arflex_host_exit_status(&h)));
	assert_int_equal(WEXITSTATUS(arflex_host_exit_status(&h)), 0);
	assert_int_equal(arflex_ctl_state(h.ctl), ARFLEX_STATE_EXITED);
	/* and removed its ctl, queues and output segment itself */
	assert_int_equal(th_leftovers(rid), 0);
	arflex_host_destroy(&h);
	assert_true(th_read_file(logpath, log, sizeof(log)) > 0);
	assert_string_equal(log, "configure\nstart\nupdate\nstop\ncleanup\n");
	unlink(logpath);
	th_assert_clean(rid);

	/* a hold of 0, not running: leaves at once */
	setup_ids("orphan0");
	assert_int_equal(probe_host(&h, "probe", 0, 0, true), 0);
	assert_int_equal(arflex_host_spawn_ex(&h, ARFLEX_PROBE_EXE, NULL, envp,
					      ARFLEX_HOST_SUPERVISOR_PIPE), 0);
	assert_int_equal(arflex_host_wait_state(&h, ARFLEX_STATE_READY, 10 * SEC), 0);
	arflex_host_drop_supervisor(&h);
	assert_int_equal(arflex_host_wait_exit(&h, 10 * SEC), 0);
	assert_int_equal(WEXITSTATUS(arflex_host_exit_status(&h)), 0);
	assert_int_equal(arflex_ctl_state(h.ctl), ARFLEX_STATE_EXITED);
	assert_true(arflex_ctl_flags(h.ctl) & ARFLEX_FLAG_SUPERVISOR_LOST);
	assert_true(arflex_ctl_flags(h.ctl) & ARFLEX_FLAG_SAFE_ACTIVE);
	assert_int_equal(th_leftovers(rid), 0);
	arflex_host_destroy(&h);
	unlink(logpath);
	th_assert_clean(rid);
}

/* A half whose output pipe lost its reader logs ("safe mode entered") and lives on. */
static void closed_output_pipe_does_not_kill(void **state)
{
	struct arflex_host h;
	uint64_t deadline;

	(void)state;
	setup_ids("sigpipe");
	assert_int_equal(probe_host(&h, "probe", 100000000, 0, true), 0);
	assert_int_equal(arflex_host_spawn_ex(&h, ARFLEX_PROBE_EXE, NULL, envp,
					      ARFLEX_HOST_OUTPUT_PIPE), 0);
	assert_int_equal(arflex_host_wait_state(&h, ARFLEX_STATE_READY, 10 * SEC), 0);
	assert_true(arflex_host_output_fd(&h) >= 0);
	arflex_host_close_output(&h);
	assert_int_equal(arflex_host_output_fd(&h), -1);
	arflex_host_heartbeat(&h);
	assert_int_equal(arflex_host_start(&h, T_CALL), 0);
	/* no heartbeat: safe mode, counted, then reported on stderr by the mailbox thread */
	deadline = arflex_sys_now_ns() + 10 * SEC;
	while (__atomic_load_n(&h.ctl->warnings[ARFLEX_WARN_SAFE], __ATOMIC_ACQUIRE) == 0 &&
	       arflex_sys_now_ns() < deadline)
		arflex_sys_sleep_until(arflex_sys_now_ns() + 1000000);
	assert_true(h.ctl->warnings[ARFLEX_WARN_SAFE] >= 1);
	/* two round trips: the serve loop reported (wrote to the dead pipe) in between */
	assert_int_equal(arflex_host_call(&h, ARFLEX_CMD_PING, NULL, NULL, T_CALL), 0);
	assert_int_equal(arflex_host_call(&h, ARFLEX_CMD_PING, NULL, NULL, T_CALL), 0);
	assert_int_equal(arflex_host_wait_exit(&h, 0), -ETIMEDOUT);
	arflex_host_heartbeat(&h);
	shutdown_ok(&h);
	assert_true(WIFEXITED(arflex_host_exit_status(&h)));
	arflex_host_destroy(&h);
	unlink(logpath);
	th_assert_clean(rid);
}

/* A process-local forger: any process of the same user can open the command queue. */
static void forge(uint16_t cmd, uint64_t token)
{
	char name[ARFLEX_OBJ_NAME_SIZE];
	struct arflex_msg m;
	mqd_t q;

	assert_int_equal(arflex_ctl_obj_name(name, sizeof(name), rid, "probe", "cmd"), 0);
	q = mq_open(name, O_WRONLY);
	assert_true(q != (mqd_t)-1);
	arflex_msg_init(&m, cmd, 77);
	m.token = token;
	assert_int_equal(mq_send(q, (const char *)&m, sizeof(m), 0), 0);
	mq_close(q);
}

static long replies_waiting(void)
{
	char name[ARFLEX_OBJ_NAME_SIZE];
	struct mq_attr a;
	mqd_t q;

	assert_int_equal(arflex_ctl_obj_name(name, sizeof(name), rid, "probe", "rsp"), 0);
	q = mq_open(name, O_RDONLY);
	assert_true(q != (mqd_t)-1);
	assert_int_equal(mq_getattr(q, &a), 0);
	mq_close(q);
	return a.mq_curmsgs;
}

/* Issue 16 finding 6 (ABI.md 5, D13): requests without the manager's token (0 or a guessed
 * one) are neither answered nor acted on, only counted; the manager's own still work. */
static void forged_requests_are_ignored(void **state)
{
	const uint16_t cmds[] = { ARFLEX_CMD_SHUTDOWN, ARFLEX_CMD_STOP, ARFLEX_CMD_RESET };
	struct arflex_host h_forged;
	struct probe_out o;
	uint64_t real;

	(void)state;
	setup_ids("forged");
	assert_int_equal(probe_host(&h_forged, "probe", 0, 0, true), 0);
	assert_int_equal(arflex_host_spawn_ex(&h_forged, ARFLEX_PROBE_EXE, NULL, envp,
					      ARFLEX_HOST_SUPERVISOR_PIPE), 0);
	assert_int_equal(arflex_host_wait_state(&h_forged, ARFLEX_STATE_READY, 10 * SEC), 0);
	assert_true(h_forged.token != 0);
	assert_int_equal(arflex_host_start(&h_forged, T_CALL), 0);
	assert_true(wait_out(&h_forged, updates_above, 5, false));

	real = h_forged.token;
	for (unsigned i = 0; i < sizeof(cmds) / sizeof(cmds[0]); i++) {
		forge(cmds[i], 0);
		forge(cmds[i], real ^ 1);
	}
	/* served in order: the forged six came before this PING */
	assert_int_equal(arflex_host_call(&h_forged, ARFLEX_CMD_PING, NULL, NULL, T_CALL), 0);
	assert_int_equal(replies_waiting(), 0);
	assert_int_equal(h_forged.ctl->warnings[ARFLEX_WARN_FORGED], 6);
	assert_int_equal(arflex_ctl_state(h_forged.ctl), ARFLEX_STATE_RUNNING);
	assert_int_equal(arflex_host_wait_exit(&h_forged, 0), -ETIMEDOUT);
	assert_true(read_out(&h_forged, &o));
	assert_true(wait_out(&h_forged, updates_above, o.updates + 5, false));
	/* a manager with the wrong token is a forger too: no reply */
	h_forged.token = real + 1;
	assert_int_equal(arflex_host_call(&h_forged, ARFLEX_CMD_STOP, NULL, NULL, SEC / 4),
			 -ETIMEDOUT);
	h_forged.token = real;
	assert_int_equal(arflex_ctl_state(h_forged.ctl), ARFLEX_STATE_RUNNING);
	assert_int_equal(h_forged.ctl->warnings[ARFLEX_WARN_FORGED], 7);
	/* the real manager's commands work */
	assert_int_equal(arflex_host_stop(&h_forged, T_CALL), 0);
	assert_int_equal(arflex_ctl_state(h_forged.ctl), ARFLEX_STATE_READY);
	shutdown_ok(&h_forged);
	arflex_host_destroy(&h_forged);
	unlink(logpath);
	th_assert_clean(rid);
}

/* A half told to expect the supervisor pipe but given no token on it (EOF at once) does not
 * serve anyone: it exits with the attach failure code. */
static void no_token_no_service(void **state)
{
	char *argv[] = { (char *)ARFLEX_PROBE_EXE, (char *)"--runtime", rid, (char *)"--instance",
			 (char *)"probe", NULL };
	struct arflex_host h;
	int sup[2], fds[3], status;
	pid_t pid;

	(void)state;
	setup_ids("notoken");
	assert_int_equal(probe_host(&h, "probe", 0, 0, true), 0);
	h.ctl->config.cfg_flags |= ARFLEX_CFG_SUPERVISOR_PIPE;
	assert_int_equal(arflex_sys_pipe(sup), 0);
	fds[0] = sup[0];
	fds[1] = fds[2] = -1;
	assert_int_equal(arflex_sys_spawn_io(&pid, ARFLEX_PROBE_EXE, argv, envp, fds), 0);
	arflex_sys_close(sup[0]);
	arflex_sys_close(sup[1]);
	assert_int_equal(waitpid(pid, &status, 0), pid);
	assert_true(WIFEXITED(status));
	assert_int_equal(WEXITSTATUS(status), ARFLEX_EXIT_ATTACH);
	assert_int_equal(arflex_ctl_state(h.ctl), ARFLEX_STATE_FAILED);
	arflex_host_destroy(&h);
	unlink(logpath);
	th_assert_clean(rid);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(supervisor_lost_holds_then_leaves_nothing),
		cmocka_unit_test(closed_output_pipe_does_not_kill),
		cmocka_unit_test(forged_requests_are_ignored),
		cmocka_unit_test(no_token_no_service),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
