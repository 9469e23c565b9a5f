/*
 * arflex/host.h - the manager side in C (tests, benchmarks, the small C launcher). The DRCR
 * does the same in Java (rt-core/docs/ABI.md).
 *
 * arflex_host_create() creates every object of one component instance exclusively (mode
 * 0600): the control block (formatted from the options), the cmd/rsp queues and one segment
 * per declared output port. arflex_host_destroy() removes all of them and reaps the child, so
 * an instance leaves nothing behind on any exit path. Caller-owned storage; one thread at a
 * time per host.
 */
#ifndef ARFLEX_HOST_H
#define ARFLEX_HOST_H

#include <stdbool.h>
#include <stdint.h>
#include <sys/types.h>

#include "arflex/component.h"
#include "arflex/control.h"
#include "arflex/mailbox.h"
#include "arflex/port.h"
#include "arflex/sys.h"

#ifdef __cplusplus
extern "C" {
#endif

/** An output port to create. */
struct arflex_host_output {
	const char *port;            /**< port name [a-z0-9_]{1,31} */
	struct arflex_port_spec spec;
};

/** Options of an instance. */
struct arflex_host_opts {
	const char *runtime;                 /**< [a-z0-9-]{1,40} */
	const char *instance;                /**< [a-z0-9-]{1,40} */
	struct arflex_ctl_config config;     /**< period etc.; see control.h */
	const struct arflex_param_slot *params; /**< descriptors; may be NULL if nparams 0 */
	unsigned nparams;
	const struct arflex_host_output *outputs; /**< may be NULL if noutputs 0 */
	unsigned noutputs;                   /**< <= ARFLEX_MAX_OUTPUTS */
	/** ABI 1.3 (D41): the state block's type; not NULL creates /arflex.<rid>.<inst>.state
	 *  (a state port of that type) as the DRCR does for a contract with <state>. */
	const struct arflex_port_type *state;
};

/** One instance. Fields are private. */
struct arflex_host {
	char runtime[ARFLEX_ID_MAX + 1];
	char instance[ARFLEX_ID_MAX + 1];
	char ctl_name[ARFLEX_OBJ_NAME_SIZE];
	struct arflex_ctl *ctl;
	struct arflex_mailbox mb;
	struct arflex_port outputs[ARFLEX_MAX_OUTPUTS];
	char output_ports[ARFLEX_MAX_OUTPUTS][ARFLEX_NAME_SIZE];
	unsigned noutputs;
	struct arflex_port state;  /**< the state block's segment (opts.state) */
	bool has_state;
	pid_t pid;          /**< 0: no child */
	int exit_status;    /**< wait status once reaped */
	bool reaped;
	uint32_t seq;
	uint64_t token;     /**< the child's mailbox token (0 without the supervisor pipe) */
	int sup_fd;         /**< write end of the child's stdin (supervisor pipe) */
	bool sup_open;
	int out_fd;         /**< read end of the child's stdout/stderr (output pipe) */
	bool out_open;
};

/** Flags of arflex_host_spawn_ex(). */
enum arflex_host_spawn_flag {
	/** The child's stdin is a pipe whose write end the host holds until the child was
	 *  reaped (or arflex_host_drop_supervisor); ARFLEX_CFG_SUPERVISOR_PIPE is set in the
	 *  control block, so the RT half takes EOF as the death of its supervisor. A fresh random
	 *  mailbox token is written first into the pipe (ABI.md 5, 6.2) and put into every
	 *  request; without this flag the token is 0 (tests and benchmarks only). */
	ARFLEX_HOST_SUPERVISOR_PIPE = 1u << 0,
	/** The child's stdout and stderr go to a pipe the host reads (arflex_host_output_fd). */
	ARFLEX_HOST_OUTPUT_PIPE = 1u << 1,
};

/** Creates every object of the instance. Returns 0 or -errno (-EINVAL: bad ids, config or
 *  parameter, message on stderr names it; -EEXIST: objects exist). On failure nothing is
 *  left behind. */
ARFLEX_API int arflex_host_create(struct arflex_host *h, const struct arflex_host_opts *o);

/** Kills the child if still running (SIGTERM, then SIGKILL after 2 s), reaps it, unmaps and
 *  unlinks every object. Safe on a failed or zeroed host. */
ARFLEX_API void arflex_host_destroy(struct arflex_host *h);

/** Spawns `@exe --runtime <rid> --instance <inst> [@extra...]` with @envp (NULL: current
 *  environment). Writes a fresh runtime heartbeat first. Returns 0 or -errno. */
ARFLEX_API int arflex_host_spawn(struct arflex_host *h, const char *exe,
				 char *const extra[], char *const envp[]);

/** As arflex_host_spawn(), with enum arflex_host_spawn_flag @flags. Returns 0 or -errno. */
ARFLEX_API int arflex_host_spawn_ex(struct arflex_host *h, const char *exe, char *const extra[],
				    char *const envp[], unsigned flags);

/** Closes the host's end of the supervisor pipe: to the RT half, as if its supervisor died. */
ARFLEX_API void arflex_host_drop_supervisor(struct arflex_host *h);

/** Read end of the child's output pipe (ARFLEX_HOST_OUTPUT_PIPE), or -1. */
ARFLEX_API int arflex_host_output_fd(const struct arflex_host *h);

/** Closes the read end of the child's output pipe (the child's writes then fail: EPIPE). */
ARFLEX_API void arflex_host_close_output(struct arflex_host *h);

/** Waits until the RT half's state word equals @state or the child exits or @timeout_ns
 *  passes. Returns 0, -ECHILD (child exited; see arflex_host_exit_status), -ETIMEDOUT. */
ARFLEX_API int arflex_host_wait_state(struct arflex_host *h, uint32_t state, uint64_t timeout_ns);

/** Waits for the child to exit (reaps it). Returns 0, -ETIMEDOUT, -ECHILD (no child). */
ARFLEX_API int arflex_host_wait_exit(struct arflex_host *h, uint64_t timeout_ns);

/** Wait status of the reaped child (as from waitpid). */
ARFLEX_API int arflex_host_exit_status(const struct arflex_host *h);

/** Sends a signal to the child. Returns 0 or -errno. */
ARFLEX_API int arflex_host_kill(struct arflex_host *h, int sig);

/** Writes the runtime heartbeat (now). Call more often than config.hb_timeout_ns. */
ARFLEX_API void arflex_host_heartbeat(struct arflex_host *h);

/** Sends command @cmd with the payload of @req (may be NULL: no payload) and waits for the
 *  reply into @rsp (may be NULL). Returns the reply status (0 or -errno from the RT half),
 *  or -ETIMEDOUT / -errno of the transport. */
ARFLEX_API int arflex_host_call(struct arflex_host *h, uint16_t cmd, const struct arflex_msg *req,
				struct arflex_msg *rsp, uint64_t timeout_ns);

/** Convenience wrappers over arflex_host_call with a timeout of @timeout_ns. */
ARFLEX_API int arflex_host_start(struct arflex_host *h, uint64_t timeout_ns);
ARFLEX_API int arflex_host_stop(struct arflex_host *h, uint64_t timeout_ns);
ARFLEX_API int arflex_host_shutdown(struct arflex_host *h, uint64_t timeout_ns);
ARFLEX_API int arflex_host_reset(struct arflex_host *h, uint64_t timeout_ns);
/** SET_PARAM by name; on success *@applied (may be NULL) = applied value bits. */
ARFLEX_API int arflex_host_set_param(struct arflex_host *h, const char *name, uint64_t bits,
				     uint64_t *applied, uint64_t timeout_ns);
ARFLEX_API int arflex_host_get_param(struct arflex_host *h, const char *name, uint64_t *bits,
				     uint64_t timeout_ns);
/** BIND input @port of this instance to the output segment @shm_name. */
ARFLEX_API int arflex_host_bind(struct arflex_host *h, const char *port, const char *shm_name,
				uint64_t timeout_ns);
ARFLEX_API int arflex_host_unbind(struct arflex_host *h, const char *port, uint64_t timeout_ns);
/** ADOPT (D41): the half takes the newest value of the state segment @shm_name over at its next
 *  START ("" withdraws it). Refused while running (-EBUSY), by a half without an adopt hook
 *  (-EOPNOTSUPP), for a segment that does not open (-ENOENT, -EPROTO...). */
ARFLEX_API int arflex_host_adopt(struct arflex_host *h, const char *shm_name, uint64_t timeout_ns);
/** READOPT (D61): the RUNNING half takes the newest value of the state segment @shm_name at its
 *  next cycle boundary (its re-adopt hook) and the reply says how that went: 0 taken, -ENOTCONN
 *  not running, -EOPNOTSUPP no re-adopt hook, -ENODATA nothing published, -ETIMEDOUT not taken
 *  within the apply deadline, the hook's own error, or the segment's open error. */
ARFLEX_API int arflex_host_readopt(struct arflex_host *h, const char *shm_name, uint64_t timeout_ns);
/** The instance's state segment (opts.state), or NULL. */
ARFLEX_API struct arflex_port *arflex_host_state(struct arflex_host *h);

/** Segment name of output @port of this instance, or NULL. */
ARFLEX_API const char *arflex_host_output_name(const struct arflex_host *h, const char *port);
/** The mapped output @port (the manager can read it too), or NULL. */
ARFLEX_API struct arflex_port *arflex_host_output(struct arflex_host *h, const char *port);

#ifdef __cplusplus
}
#endif
#endif /* ARFLEX_HOST_H */
