/*
 * arflex/mailbox.h - the command protocol over POSIX message queues.
 *
 * Two queues per component instance, both created by the manager (O_CREAT|O_EXCL, 0600,
 * mq_maxmsg = ARFLEX_MQ_MAXMSG, mq_msgsize = ARFLEX_MSG_SIZE) and removed by it:
 *   /arflex.<rid>.<inst>.cmd   manager -> RT process (requests)
 *   /arflex.<rid>.<inst>.rsp   RT process -> manager (replies)
 * Every message is exactly one struct arflex_msg (512 bytes). A reply echoes the request's
 * seq and cmd, sets ARFLEX_MSG_REPLY in flags and carries status 0 or a negative errno.
 * Requests are served one at a time, in order, by the RT process's mailbox thread (lower
 * priority than the RT thread, never the RT thread itself). The manager should have one
 * request outstanding at a time and discard replies whose seq is not the one it waits for
 * (a late reply to a request that timed out).
 *
 * Only the manager may command (ABI.md 5, DECISIONS.md D13): with ARFLEX_CFG_SUPERVISOR_PIPE
 * the manager writes a random 64-bit token as the first 8 bytes (little endian) into the
 * supervisor pipe (the child's stdin) and puts it into msg.token of every request. The RT half
 * reads it before it serves anything and ignores (no reply, no action) every request whose
 * token differs; replies echo the token and the manager discards replies with another one. The
 * token is never in shared memory. Without the pipe the token is 0 (tests and benchmarks only).
 */
#ifndef ARFLEX_MAILBOX_H
#define ARFLEX_MAILBOX_H

#include <mqueue.h>
#include <stdbool.h>
#include <stdint.h>

#include "arflex/control.h"
#include "arflex/sys.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Magic of a message: "AFMS" as little-endian uint32. */
#define ARFLEX_MSG_MAGIC 0x534D4641u
/** Size of every message and the queues' mq_msgsize. */
#define ARFLEX_MSG_SIZE 512u
/** mq_maxmsg of both queues (the system limit here is 10). */
#define ARFLEX_MQ_MAXMSG 8
/** Payload bytes. */
#define ARFLEX_MSG_PAYLOAD (ARFLEX_MSG_SIZE - 32u)

/** Commands (msg.cmd). Status values in the reply are listed per command in ABI.md. */
enum arflex_cmd {
	ARFLEX_CMD_START = 1,     /**< READY -> RUNNING */
	ARFLEX_CMD_STOP = 2,      /**< RUNNING -> READY */
	ARFLEX_CMD_SET_PARAM = 3, /**< payload param; reply param with applied value */
	ARFLEX_CMD_GET_PARAM = 4, /**< payload param (index or name); reply param */
	ARFLEX_CMD_BIND = 5,      /**< payload bind: input port + provider segment name */
	ARFLEX_CMD_UNBIND = 6,    /**< payload bind (port only) */
	ARFLEX_CMD_GET_STATE = 7, /**< reply state */
	ARFLEX_CMD_GET_STATS = 8, /**< reply stats */
	ARFLEX_CMD_RESET = 9,     /**< operator reset: leave safe mode / clear reset-required */
	ARFLEX_CMD_SHUTDOWN = 10, /**< stop if running, cleanup, exit 0 (reply sent first) */
	ARFLEX_CMD_PING = 11,     /**< no-op round trip (benchmarks, liveness) */
	ARFLEX_CMD_ADOPT = 12,    /**< ABI 1.3: payload bind, shm_name = the state segment of the
				   *  half this one replaces; adopted at the next START (D41) */
	ARFLEX_CMD_READOPT = 13,  /**< D61: payload bind, shm_name = the state segment of the
				   *  half this one replaces; a RUNNING half takes its newest value
				   *  at its next cycle boundary (re-adopt hook); reply when taken */
};

/** msg.flags bits. */
#define ARFLEX_MSG_REPLY 0x1u

/** SET_PARAM / GET_PARAM payload, both directions. */
struct arflex_msg_param {
	uint32_t index;          /**< slot; UINT32_MAX: look up by name */
	uint32_t type;           /**< reply: enum arflex_param_type */
	uint64_t value;          /**< request: value bits to set; reply: applied value bits */
	uint64_t applied_seq;    /**< reply: the slot's applied_seq */
	char name[ARFLEX_NAME_SIZE]; /**< used when index == UINT32_MAX; reply: the name */
};

/** BIND / UNBIND payload. */
struct arflex_msg_bind {
	char port[ARFLEX_NAME_SIZE];         /**< input port name of the receiving component */
	char shm_name[ARFLEX_OBJ_NAME_SIZE]; /**< provider output segment ("" for UNBIND) */
};

/** GET_STATE reply. */
struct arflex_msg_state {
	uint32_t state;          /**< enum arflex_rt_state */
	uint32_t flags;          /**< enum arflex_ctl_flag */
	int32_t pid;
	uint32_t bound_inputs;   /**< bit i: input i bound */
	uint64_t cycles;
};

/** A metric summary in GET_STATS. */
struct arflex_msg_metric {
	uint64_t min_ns, max_ns, mean_ns, mad_ns, p50_ns, p99_ns, p999_ns;
};

/** GET_STATS reply. */
struct arflex_msg_stats {
	uint64_t cycles;
	uint64_t overruns;
	uint64_t deadline_misses;
	uint64_t update_errors;
	struct arflex_msg_metric latency;
	struct arflex_msg_metric exec;
};

/** One message, 512 bytes. */
struct arflex_msg {
	uint32_t magic;          /**< ARFLEX_MSG_MAGIC */
	uint16_t abi_major;
	uint16_t abi_minor;
	uint32_t seq;            /**< chosen by the requester, echoed in the reply */
	uint16_t cmd;            /**< enum arflex_cmd */
	uint16_t flags;          /**< ARFLEX_MSG_REPLY on replies */
	int32_t status;          /**< reply: 0 or -errno; request: 0 */
	uint32_t payload_len;    /**< bytes of payload in use */
	uint64_t token;          /**< the instance's secret (see above); echoed in the reply */
	union {
		uint8_t raw[ARFLEX_MSG_PAYLOAD];
		struct arflex_msg_param param;
		struct arflex_msg_bind bind;
		struct arflex_msg_state state;
		struct arflex_msg_stats stats;
	} u;
};

ARFLEX_STATIC_ASSERT(sizeof(struct arflex_msg) == ARFLEX_MSG_SIZE, "msg size");
ARFLEX_STATIC_ASSERT(offsetof(struct arflex_msg, token) == 24, "msg token");
ARFLEX_STATIC_ASSERT(offsetof(struct arflex_msg, u) == 32, "msg payload");
ARFLEX_STATIC_ASSERT(sizeof(struct arflex_msg_param) == 56, "msg param");
ARFLEX_STATIC_ASSERT(sizeof(struct arflex_msg_bind) == 160, "msg bind");
ARFLEX_STATIC_ASSERT(sizeof(struct arflex_msg_stats) == 144, "msg stats");

/** A pair of open queues. Caller-owned storage. */
struct arflex_mailbox {
	mqd_t tx;                /**< we send here */
	mqd_t rx;                /**< we receive here */
	bool owner;              /**< created by us: deinit unlinks */
	char tx_name[ARFLEX_OBJ_NAME_SIZE];
	char rx_name[ARFLEX_OBJ_NAME_SIZE];
};

/**
 * Manager side: creates cmd and rsp of (@rid, @inst) exclusively (0600) and opens them
 * (tx = cmd, rx = rsp). Returns 0 or -errno (-EINVAL bad ids, -EEXIST); nothing is left
 * behind on failure.
 */
ARFLEX_API int arflex_mailbox_create(struct arflex_mailbox *mb, const char *rid,
				     const char *inst);

/** RT side: opens the existing queues (tx = rsp, rx = cmd), never creating them, and checks
 *  their attributes. Returns 0 or -errno (-ENOENT, -EPROTO for wrong mq attributes). */
ARFLEX_API int arflex_mailbox_attach(struct arflex_mailbox *mb, const char *rid,
				     const char *inst);

/** Closes both queues; the owner (manager) also unlinks them. */
ARFLEX_API void arflex_mailbox_deinit(struct arflex_mailbox *mb);

/** Fills magic/ABI/seq/cmd of @m and zeroes the rest. */
ARFLEX_API void arflex_msg_init(struct arflex_msg *m, uint16_t cmd, uint32_t seq);

/** Checks magic and ABI major of a received message of @len bytes. Returns 0 or -EPROTO. */
ARFLEX_API int arflex_msg_check(const struct arflex_msg *m, long len);

/** Sends @m, waiting at most @timeout_ns (0: fail at once when full). Returns 0 or -errno. */
ARFLEX_API int arflex_mailbox_send(struct arflex_mailbox *mb, const struct arflex_msg *m,
				   uint64_t timeout_ns);

/** Receives into @m, waiting at most @timeout_ns. Returns 0, -ETIMEDOUT, -EPROTO (bad
 *  message; it is consumed) or another -errno. */
ARFLEX_API int arflex_mailbox_recv(struct arflex_mailbox *mb, struct arflex_msg *m,
				   uint64_t timeout_ns);

/** Manager side: sends @req and waits for the reply with the same seq and token, discarding
 *  stale replies and replies with another token, until @timeout_ns has passed. On success the reply is in @rsp and its status is
 *  returned (0 or -errno from the RT side); -ETIMEDOUT or another -errno on transport
 *  failure. */
ARFLEX_API int arflex_mailbox_call(struct arflex_mailbox *mb, const struct arflex_msg *req,
				   struct arflex_msg *rsp, uint64_t timeout_ns);

/** Name of a command ("START"...), "?" for unknown. */
ARFLEX_API const char *arflex_cmd_name(unsigned cmd);

#ifdef __cplusplus
}
#endif
#endif /* ARFLEX_MAILBOX_H */
