/*
 * arflex/component.h - the template of an RT half: an ops struct and arflex_component_main().
 *
 *   static const struct arflex_component_ops ops = {
 *           .name = "gain", .configure = my_configure, .update = my_update,
 *   };
 *   int main(int argc, char **argv) { return arflex_component_main(argc, argv, &ops); }
 *
 * arflex_component_main() does everything else:
 *   1. parses `--runtime <rid> --instance <inst>` (also --help, --version);
 *   2. opens (never creates) /arflex.<rid>.<inst>.ctl, checks magic/ABI/size, writes its pid,
 *      state CONFIGURING, applies parameter defaults; opens the cmd/rsp queues;
 *   3. calls configure (main thread), where the component declares its ports with
 *      arflex_component_output() / arflex_component_input() and looks up its parameters;
 *   4. state READY; the mailbox thread serves commands (START, STOP, SET_PARAM, GET_PARAM,
 *      BIND, UNBIND, GET_STATE, GET_STATS, RESET, SHUTDOWN, PING, ADOPT, READOPT);
 *      ADOPT (before START, D41) names the state segment of the half this one replaces: at
 *      the next START, right after the start hook, its newest value goes to the adopt hook;
 *      READOPT (while running, D61) names it again: at the next cycle boundary its newest
 *      value goes to the re-adopt hook (arflex_component_readopt), before that cycle's update;
 *   5. on START: the RT thread (arflex_task: SCHED_FIFO at config.priority when permitted,
 *      affinity config.cpu_mask, mlockall, cpu_dma_latency) calls start, then every period:
 *      picks up new input bindings and parameter requests (cycle boundary), checks the
 *      runtime heartbeat, writes its own heartbeat, calls update (or safe), records stats;
 *      on STOP it calls stop and returns to READY;
 *   6. on SHUTDOWN or SIGTERM/SIGINT: stops the loop if running, calls cleanup, unmaps
 *      everything, state EXITED, returns 0. If configure fails: state FAILED, ctl.exit_status
 *      = the error, nothing is left mapped, returns ARFLEX_EXIT_CONFIGURE.
 *
 * Safe mode: when config.hb_timeout_ns > 0 and the runtime heartbeat (ctl.runtime_hb_ns) is
 * older than that, the RT thread sets ARFLEX_FLAG_SAFE_ACTIVE and calls safe instead of
 * update every cycle. When the heartbeat is fresh again: without ARFLEX_CFG_MOVES_HARDWARE
 * safe mode ends by itself; with it, ARFLEX_FLAG_RESET_REQUIRED is set and safe mode lasts
 * until the operator's RESET command (which fails with -EAGAIN while the heartbeat is stale,
 * and with -EBUSY while the component's hold word names a safety input: the cause persists).
 * "Older than that" is judged over the RT thread's own cycling time (arflex_hb_judge): each
 * cycle adds at most two periods to the runtime's silence, so a stall of the whole machine
 * that delays the RT thread too is not taken for a silent runtime (ABI.md 6).
 *
 * Supervisor death (ABI.md 6.2): SIGPIPE is ignored and stdout/stderr pipes are made
 * non-blocking, so a dead supervisor can neither kill nor block the process. With
 * ARFLEX_CFG_SUPERVISOR_PIPE a watcher thread reads fd 0; EOF sets
 * ARFLEX_FLAG_SUPERVISOR_LOST, and the RT thread enters safe mode in that cycle (latching
 * ARFLEX_FLAG_RESET_REQUIRED for ARFLEX_CFG_MOVES_HARDWARE). After config.orphan_hold_ns the
 * mailbox thread leaves as on SHUTDOWN (stop, cleanup, EXITED, exit 0) and unlinks the
 * instance's ctl, queues and output segments: no manager is left to do it.
 *
 * Threads: configure and cleanup run on the main thread; start, update, safe and stop on the
 * RT thread; commands on the mailbox thread. Hooks never run concurrently with each other.
 */
#ifndef ARFLEX_COMPONENT_H
#define ARFLEX_COMPONENT_H

#include <stdbool.h>
#include <stdint.h>

#include "arflex/control.h"
#include "arflex/port.h"
#include "arflex/sys.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Maximum ports of each direction per component. */
#define ARFLEX_MAX_INPUTS 16
#define ARFLEX_MAX_OUTPUTS 16

/** Process exit codes of arflex_component_main. */
enum arflex_exit {
	ARFLEX_EXIT_OK = 0,        /**< SHUTDOWN or SIGTERM, clean */
	ARFLEX_EXIT_USAGE = 2,     /**< bad command line */
	ARFLEX_EXIT_ATTACH = 3,    /**< control block or queues missing or incompatible */
	ARFLEX_EXIT_CONFIGURE = 4, /**< configure hook or port declaration failed */
	ARFLEX_EXIT_RUNTIME = 5,   /**< fatal error after configure */
};

struct arflex_component; /* opaque, one per process */

/** A state block handed over from the half this one replaces (D41), for the adopt hook. */
struct arflex_adopted_state {
	const char *type_name; /**< its port type, e.g. "arflex.TrajectoryState" */
	uint16_t major;        /**< its type version */
	uint16_t minor;
	const void *data;      /**< the newest value the old half published (valid in the hook) */
	uint32_t length;       /**< bytes at data: the old segment's elem_size */
	uint64_t age_ns;       /**< how old that value was when it was read */
};
struct arflex_input;     /* opaque, one per declared input */

/**
 * The hooks of a component. @user is ops->user. Return conventions: 0 or a negative errno.
 */
struct arflex_component_ops {
	/** Component name for messages (optional; default "component"). */
	const char *name;
	/** Passed to every hook (optional). */
	void *user;
	/** OPTIONAL, main thread, once: declare ports, look up parameters, allocate. < 0 aborts
	 *  the process start (state FAILED; cleanup is NOT called: undo your own partial work). */
	int (*configure)(struct arflex_component *c, void *user);
	/** OPTIONAL, RT thread, at each START before the first cycle: prefault, reset state.
	 *  < 0 refuses the START (its reply carries the error; state stays READY). */
	int (*start)(struct arflex_component *c, void *user);
	/** REQUIRED, RT thread, once per period: read inputs, compute, write outputs. Must not
	 *  block, allocate or print. < 0 is counted (stats.update_errors) and the loop goes on. */
	int (*update)(struct arflex_component *c, void *user, uint64_t release_ns);
	/** OPTIONAL, RT thread, after the last cycle of a run (STOP, SHUTDOWN, SIGTERM). */
	void (*stop)(struct arflex_component *c, void *user);
	/** OPTIONAL, main thread, once before exit if configure succeeded: free resources. */
	void (*cleanup)(struct arflex_component *c, void *user);
	/** OPTIONAL (REQUIRED in practice when the component moves hardware), RT thread, every
	 *  cycle while safe mode is active, instead of update; @first is true on the first call
	 *  of a safe episode. Drive outputs as @mode says (hold or zero). No safe hook: outputs
	 *  simply stop changing (hold). Return as update. */
	int (*safe)(struct arflex_component *c, void *user, enum arflex_safe_mode mode,
		    bool first);
	/** OPTIONAL (ABI 1.3, D41), RT thread, once, right after start at the first START after
	 *  an ADOPT: take over the state block @s of the half this one replaces (the newest value
	 *  it published), so the first update continues where the old half was. @s says its type
	 *  and version: convert an older one (the contract's <convertsFrom>), refuse what is not
	 *  understood. Must not block, allocate or print. < 0 refuses the START (its reply
	 *  carries the error). Without this hook the manager's ADOPT is refused (-EOPNOTSUPP). */
	int (*adopt)(struct arflex_component *c, void *user, const struct arflex_adopted_state *s);
};

/** Runs an RT half. Returns an enum arflex_exit code for main() to return. */
ARFLEX_API int arflex_component_main(int argc, char **argv,
				     const struct arflex_component_ops *ops);

/* ---- for configure ------------------------------------------------------------------- */

/**
 * Opens the output port @port (segment /arflex.<rid>.<inst>.out.<port>, created by the
 * manager) as its producer, checking @method and @type exactly. On success *@out points to
 * the port (owned by the library, valid until exit). Configure only. Returns 0 or -errno
 * (-ENOENT: the manager did not create it; -EPROTOTYPE: type/method mismatch; -ENOSPC: too
 * many outputs; -EEXIST: declared twice).
 */
ARFLEX_API int arflex_component_output(struct arflex_component *c, const char *port,
				       enum arflex_port_method method,
				       const struct arflex_port_type *type,
				       struct arflex_port **out);

/** Declares the input @port; it stays unbound until a BIND names a provider segment, whose
 *  header must be compatible with @method and @type. *@out is owned by the library.
 *  Configure only. Returns 0 or -errno (-EINVAL, -ENOSPC, -EEXIST). */
ARFLEX_API int arflex_component_input(struct arflex_component *c, const char *port,
				      enum arflex_port_method method,
				      const struct arflex_port_type *type,
				      struct arflex_input **out);

/**
 * The state block (D41): opens /arflex.<rid>.<inst>.state, created by the manager when the
 * contract declares <state type=...> (SPEC 12.1), as its producer, checking @type exactly.
 * Configure only. Returns 0 (*@out, if not NULL, is the port; publish with
 * arflex_component_state_publish), -ENOENT (the manager made no state segment: the contract
 * declares none, or a host test runs without one; publishing is then a no-op), -EEXIST
 * (declared twice), -EPROTOTYPE (type mismatch) or another -errno.
 */
ARFLEX_API int arflex_component_state(struct arflex_component *c,
				      const struct arflex_port_type *type,
				      struct arflex_port **out);
/** Publishes the state block (a seqlock state write stamped @stamp_ns, as
 *  arflex_state_write_at): every cycle, after the outputs. 0 without a state segment. RT safe:
 *  no blocking, no allocation. */
ARFLEX_API int arflex_component_state_publish(struct arflex_component *c, const void *val,
					      size_t len, uint64_t stamp_ns);
/** The hook type of arflex_component_adopt_prepare. */
typedef int (*arflex_adopt_prepare_fn)(struct arflex_component *c, void *user,
				       const struct arflex_adopted_state *s);
/**
 * D57: registers @fn (NULL: none), called on the MAILBOX thread when an ADOPT arrives (before
 * START) with the newest value the old half has published by then (not called when it has
 * published none). A half that needs more than its state block to take over (teach's recording,
 * kept in a file) reads it there, off the RT thread: @fn may block, allocate and print. The
 * adopt hook at START still gets the newest value then and decides. A negative return refuses
 * the ADOPT (the reply carries the error; the manager tears the new half down, nothing
 * changed). Configure only (a function, not an ops member, so that the ops struct and every
 * component's initializer of it stay as they are). Returns 0 or -EINVAL.
 */
ARFLEX_API int arflex_component_adopt_prepare(struct arflex_component *c, arflex_adopt_prepare_fn fn);
/** The hook type of arflex_component_readopt (the adopt hook's). */
typedef int (*arflex_readopt_fn)(struct arflex_component *c, void *user,
				 const struct arflex_adopted_state *s);
/**
 * D61: registers @fn (NULL: none), called on the RT THREAD at a cycle boundary, before that
 * cycle's update, when the manager sends READOPT to the RUNNING half: the newest value the
 * half this one replaces has published then, to take over again (the switch of an update whose
 * new half ran in shadow, its outputs not applied, since its START). As the adopt hook: convert
 * or refuse what is not understood; must not block, allocate or print; @s is valid in the hook
 * only. A negative return is the READOPT's reply (the manager then keeps the old half and stops
 * this one: fail closed); the hook must leave the half's state as it was when it refuses. A
 * half without the hook refuses READOPT (-EOPNOTSUPP). For a component whose adopt hook may
 * run between two updates, the adopt hook itself. Configure only. Returns 0 or -EINVAL. A hook
 * registered when configure returns is advertised in the control block before READY
 * (ARFLEX_FLAG_READOPT, D70): the manager runs a half in shadow only when it can re-adopt.
 */
ARFLEX_API int arflex_component_readopt(struct arflex_component *c, arflex_readopt_fn fn);
/** True when the state segment is open (arflex_component_state returned 0). */
ARFLEX_API bool arflex_component_state_open(const struct arflex_component *c);

/** Index of parameter @name in the control block, or -ENOENT. */
ARFLEX_API int arflex_component_param(const struct arflex_component *c, const char *name);

/* ---- for update / safe (RT safe) ----------------------------------------------------- */

/** Parameter value in force (changes only between cycles while running). */
ARFLEX_API int64_t arflex_param_i64(const struct arflex_component *c, int idx);
ARFLEX_API double arflex_param_f64(const struct arflex_component *c, int idx);
ARFLEX_API bool arflex_param_bool(const struct arflex_component *c, int idx);
/** A number that changes with every write of parameter @idx that was taken, also of the same
 *  value (the slot's applied sequence). A component that takes a write as a command (a fresh
 *  "run" after a stop) compares it with the one it saw last. */
ARFLEX_API uint64_t arflex_param_writes(const struct arflex_component *c, int idx);

/** True while an input has a provider. */
ARFLEX_API bool arflex_input_bound(const struct arflex_input *in);
/** Which binding the input is on: 0 while unbound, else a number that is different for every
 *  BIND or REBIND the RT thread has taken (also when the same provider is bound again after
 *  an unbind). A change means "another provider, or the same one restarted": a consumer that
 *  must not carry state across providers (a motion source following the measured arm, a
 *  robot accepting a reference) compares it with the one it last saw. */
ARFLEX_API uint32_t arflex_input_binding(const struct arflex_input *in);
/** The bound provider's mapping (read-only use), NULL while unbound. Valid until the next
 *  cycle boundary (a REBIND is taken there). RT safe. */
ARFLEX_API struct arflex_port *arflex_input_port(struct arflex_input *in);
/** arflex_port_age on the bound provider (age of its newest value at @now_ns, header
 *  re-checked); -ENOTCONN when unbound. RT safe. */
ARFLEX_API int arflex_input_age(const struct arflex_input *in, uint64_t now_ns, uint64_t *age_ns);
/** arflex_state_read on the bound provider; -ENOTCONN when unbound. A damaged provider
 *  header (-EPROTO) is counted as a rejected value of the input (arflex_input_reject). RT
 *  safe. */
ARFLEX_API int arflex_input_state_read(struct arflex_input *in, void *out, size_t len,
				       uint64_t *seq);
/** arflex_stream_pop on the bound provider; -ENOTCONN when unbound; -EPROTO counted. */
ARFLEX_API int arflex_input_stream_pop(struct arflex_input *in, void *out, size_t len);
/** arflex_frame_acquire on the bound provider; -ENOTCONN when unbound; -EPROTO counted. */
ARFLEX_API int arflex_input_frame_acquire(struct arflex_input *in, struct arflex_frame_view *v);
/** The component refused the newest value of @in (its validator: NaN, Inf, out of range).
 *  Counts it in the input's slot of the control block (ctl.inputs, ABI 1.2: the DRCR shows
 *  rejected values per input and its provider) and in the ARFLEX_WARN_INPUT warning. The
 *  count starts at 0 with each run of the RT half. RT safe (two atomic adds). */
ARFLEX_API void arflex_input_reject(struct arflex_input *in);

/** The control block (read-only use; e.g. config.period_ns). */
ARFLEX_API const struct arflex_ctl *arflex_component_ctl(const struct arflex_component *c);

/** @period_ns in seconds, the time step of a control law: equal to the decimal constant a
 *  legacy loop wrote for it (`#define DT 0.009` for 9 ms, bit for bit), at every period. The
 *  division is rounded once from the exact quotient, as the compiler rounds that literal;
 *  period_ns * 1e-9 multiplies by an inexact 1e-9 and differs at 9, 11, 13 ms and 40% of all
 *  whole-microsecond periods (rt-core/template/GUIDE.md, "A bit-exact time step"; ctest
 *  rt.template.dt). Usage: dt = arflex_period_s(arflex_component_ctl(c)->config.period_ns). */
static inline double arflex_period_s(uint64_t period_ns)
{
	return (double)period_ns / 1e9;
}
/** Runtime id and instance name. */
ARFLEX_API const char *arflex_component_runtime(const struct arflex_component *c);
ARFLEX_API const char *arflex_component_instance(const struct arflex_component *c);
/** True while safe mode is active. */
ARFLEX_API bool arflex_component_safe_active(const struct arflex_component *c);
/** Latches an operator reset (e.g. a safety trip): atomically sets ARFLEX_FLAG_RESET_REQUIRED
 *  in the control block. From the next cycle on the RT thread calls the safe hook instead of
 *  update until the operator's RESET command (arflex_host_reset / the DRCR's reset) clears
 *  the flag; the flag survives a restart of the RT process. Idempotent. RT safe: one atomic
 *  OR, callable from any hook or thread of the component. */
ARFLEX_API void arflex_component_require_reset(struct arflex_component *c);

/** Says why the component holds the arm by itself (ctl->hold, shown by the runtime with the
 *  state): @cause an enum arflex_hold_cause (ARFLEX_HOLD_NONE clears), @detail and @input as
 *  documented there. Written only when it changes. RT safe: one atomic store. */
ARFLEX_API void arflex_component_hold(struct arflex_component *c, uint32_t cause, uint32_t detail,
				      uint32_t input);
/** Index of @in among the component's inputs (declaration order), for arflex_component_hold. */
ARFLEX_API uint32_t arflex_input_index(const struct arflex_component *c,
				       const struct arflex_input *in);

#ifdef __cplusplus
}
#endif
#endif /* ARFLEX_COMPONENT_H */
