/* The command protocol over a pair of POSIX message queues. */
#include "arflex/mailbox.h"

#include <errno.h>
#include <fcntl.h>
#include <string.h>

static int names(struct arflex_mailbox *mb, const char *rid, const char *inst, bool manager)
{
	int r = arflex_ctl_obj_name(manager ? mb->tx_name : mb->rx_name, ARFLEX_OBJ_NAME_SIZE,
				    rid, inst, "cmd");

	if (r)
		return r;
	return arflex_ctl_obj_name(manager ? mb->rx_name : mb->tx_name, ARFLEX_OBJ_NAME_SIZE,
				   rid, inst, "rsp");
}

int arflex_mailbox_create(struct arflex_mailbox *mb, const char *rid, const char *inst)
{
	struct mq_attr attr = { .mq_maxmsg = ARFLEX_MQ_MAXMSG, .mq_msgsize = ARFLEX_MSG_SIZE };
	int r;

	memset(mb, 0, sizeof(*mb));
	mb->tx = mb->rx = (mqd_t)-1;
	r = names(mb, rid, inst, true);
	if (r)
		return r;
	r = arflex_sys_mq_open(&mb->tx, mb->tx_name, O_CREAT | O_EXCL | O_RDWR, 0600, &attr);
	if (r)
		return r;
	r = arflex_sys_mq_open(&mb->rx, mb->rx_name, O_CREAT | O_EXCL | O_RDWR, 0600, &attr);
	if (r)
		goto out_tx;
	mb->owner = true;
	return 0;

out_tx:
	arflex_sys_mq_close(mb->tx);
	arflex_sys_mq_unlink(mb->tx_name);
	mb->tx = (mqd_t)-1;
	return r;
}

static int check_attr(mqd_t q)
{
	struct mq_attr a;
	int r = arflex_sys_mq_getattr(q, &a);

	if (r)
		return r;
	if (a.mq_msgsize != ARFLEX_MSG_SIZE)
		return -EPROTO;
	return 0;
}

int arflex_mailbox_attach(struct arflex_mailbox *mb, const char *rid, const char *inst)
{
	int r;

	memset(mb, 0, sizeof(*mb));
	mb->tx = mb->rx = (mqd_t)-1;
	r = names(mb, rid, inst, false);
	if (r)
		return r;
	r = arflex_sys_mq_open(&mb->rx, mb->rx_name, O_RDWR, 0, NULL);
	if (r)
		return r;
	r = arflex_sys_mq_open(&mb->tx, mb->tx_name, O_RDWR, 0, NULL);
	if (r)
		goto out_rx;
	r = check_attr(mb->rx);
	if (r)
		goto out_tx;
	r = check_attr(mb->tx);
	if (r)
		goto out_tx;
	return 0;

out_tx:
	arflex_sys_mq_close(mb->tx);
	mb->tx = (mqd_t)-1;
out_rx:
	arflex_sys_mq_close(mb->rx);
	mb->rx = (mqd_t)-1;
	return r;
}

void arflex_mailbox_deinit(struct arflex_mailbox *mb)
{
	if (mb->tx != (mqd_t)-1 && mb->tx_name[0])
		arflex_sys_mq_close(mb->tx);
	if (mb->rx != (mqd_t)-1 && mb->rx_name[0])
		arflex_sys_mq_close(mb->rx);
	if (mb->owner) {
		arflex_sys_mq_unlink(mb->tx_name);
		arflex_sys_mq_unlink(mb->rx_name);
	}
	memset(mb, 0, sizeof(*mb));
	mb->tx = mb->rx = (mqd_t)-1;
}

void arflex_msg_init(struct arflex_msg *m, uint16_t cmd, uint32_t seq)
{
	memset(m, 0, sizeof(*m));
	m->magic = ARFLEX_MSG_MAGIC;
	m->abi_major = ARFLEX_ABI_MAJOR;
	m->abi_minor = ARFLEX_ABI_MINOR;
	m->seq = seq;
	m->cmd = cmd;
}

int arflex_msg_check(const struct arflex_msg *m, long len)
{
	if (len != (long)ARFLEX_MSG_SIZE || m->magic != ARFLEX_MSG_MAGIC ||
	    m->abi_major != ARFLEX_ABI_MAJOR || m->payload_len > ARFLEX_MSG_PAYLOAD)
		return -EPROTO;
	return 0;
}

int arflex_mailbox_send(struct arflex_mailbox *mb, const struct arflex_msg *m,
			uint64_t timeout_ns)
{
	struct timespec ts = arflex_sys_realtime_in(timeout_ns);

	return arflex_sys_mq_timedsend(mb->tx, m, sizeof(*m), &ts);
}

int arflex_mailbox_recv(struct arflex_mailbox *mb, struct arflex_msg *m, uint64_t timeout_ns)
{
	struct timespec ts = arflex_sys_realtime_in(timeout_ns);
	long n = arflex_sys_mq_timedreceive(mb->rx, m, sizeof(*m), &ts);

	if (n < 0)
		return (int)n;
	return arflex_msg_check(m, n);
}

int arflex_mailbox_call(struct arflex_mailbox *mb, const struct arflex_msg *req,
			struct arflex_msg *rsp, uint64_t timeout_ns)
{
	uint64_t deadline = arflex_sys_now_ns() + timeout_ns;
	int r;

	r = arflex_mailbox_send(mb, req, timeout_ns);
	if (r)
		return r;
	for (;;) {
		uint64_t now = arflex_sys_now_ns();

		if (now >= deadline)
			return -ETIMEDOUT;
		r = arflex_mailbox_recv(mb, rsp, deadline - now);
		if (r == -EPROTO)
			continue; /* malformed: dropped */
		if (r)
			return r;
		if (rsp->seq == req->seq && rsp->cmd == req->cmd && rsp->token == req->token &&
		    (rsp->flags & ARFLEX_MSG_REPLY))
			return rsp->status;
		/* stale reply of an earlier, timed-out request, or not from our RT half: discard */
	}
}

const char *arflex_cmd_name(unsigned cmd)
{
	static const char *const n[] = { "?", "START", "STOP", "SET_PARAM", "GET_PARAM", "BIND",
					 "UNBIND", "GET_STATE", "GET_STATS", "RESET", "SHUTDOWN",
					 "PING", "ADOPT", "READOPT" };

	return cmd < sizeof(n) / sizeof(n[0]) ? n[cmd] : "?";
}
