/*
 * arflex/control.h - the control block: one shared-memory segment per component instance,
 * /arflex.<runtime-id>.<instance>.ctl, created and initialised by the manager (DRCR or the C
 * host API), opened read-write by the RT process. See rt-core/docs/ABI.md for the byte layout
 * and the protocol; the structs below ARE that layout (x86-64, little endian, fixed-width
 * fields, natural alignment, offsets pinned by static asserts).
 *
 * Concurrency rules (who writes what):
 *   - header, config, parameter descriptors (name/type/range/default/mutable): the manager,
 *     before spawning the RT process; read-only afterwards.
 *   - runtime_hb_ns: the manager, periodically (CLOCK_MONOTONIC ns).
 *   - state, pid, flags (after spawn), rt_hb_ns, stats, warnings, parameter applied side:
 *     the RT process only.
 *   - parameter requested side (req_seq/req_value): one requester per slot (the manager
 *     directly, or the RT process's mailbox thread acting for SET_PARAM), see ABI.md.
 * All shared words are accessed with atomic loads/stores (acquire/release); the statistics
 * are published under a seqlock. No lock lives in shared memory.
 */
#ifndef ARFLEX_CONTROL_H
#define ARFLEX_CONTROL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "arflex/sys.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- ABI identification (shared by every arflex shared object) ---------------------- */

/** ABI major: a reader refuses an object whose major differs. */
#define ARFLEX_ABI_MAJOR 1u
/** ABI minor: additions only; a reader accepts any minor >= the one it needs.
 *  1.1: config.orphan_hold_ns, ARFLEX_CFG_SUPERVISOR_PIPE, ARFLEX_FLAG_SUPERVISOR_LOST.
 *  1.2: inputs[]: rejected values counted per input (in the former tail padding). */
#define ARFLEX_ABI_MINOR 3u

/** Magic of the control block: bytes "ARFLXCTL" read as little-endian uint64. */
#define ARFLEX_CTL_MAGIC UINT64_C(0x4C5443584C465241)

/** Maximum length of a runtime id or instance name (pattern [a-z0-9-]{1,40}). */
#define ARFLEX_ID_MAX 40
/** Size of a name field holding a port or parameter name, NUL included. */
#define ARFLEX_NAME_SIZE 32
/** Size of a shared-object name field ("/arflex.<rid>.<inst>.<channel>"), NUL included. */
#define ARFLEX_OBJ_NAME_SIZE 128

/** Number of parameter slots in the control block. */
#define ARFLEX_PARAM_SLOTS 64
/** Histogram: bin width in ns, number of regular bins (bin i covers [i*W, (i+1)*W)). A last
 *  extra bin counts every sample >= ARFLEX_HIST_BINS * ARFLEX_HIST_BIN_NS (200 us). */
#define ARFLEX_HIST_BIN_NS 100u
#define ARFLEX_HIST_BINS 2000u
/** Number of warning kinds counted in the control block. */
#define ARFLEX_WARN_KINDS 16

/* ---- state word --------------------------------------------------------------------- */

/** State of the RT half, written by the RT process only. */
enum arflex_rt_state {
	ARFLEX_STATE_CREATED = 0,     /**< manager created the block; no process attached yet */
	ARFLEX_STATE_CONFIGURING = 1, /**< process attached, configure hook running */
	ARFLEX_STATE_READY = 2,       /**< configured, waiting for START (also after STOP) */
	ARFLEX_STATE_RUNNING = 3,     /**< RT thread cycling */
	ARFLEX_STATE_STOPPING = 4,    /**< STOP received, RT thread finishing */
	ARFLEX_STATE_EXITED = 5,      /**< cleanup done, process exiting normally */
	ARFLEX_STATE_FAILED = 6,      /**< configure or start failed, or fatal error; exiting */
};

/** Bits of ctl->flags. Before the spawn the manager may set ARFLEX_FLAG_RESET_REQUIRED;
 *  afterwards only the RT process writes the word. */
enum arflex_ctl_flag {
	ARFLEX_FLAG_SCHED_FIFO = 1u << 0,     /**< RT thread got SCHED_FIFO at config priority */
	ARFLEX_FLAG_MLOCKALL = 1u << 1,       /**< mlockall(MCL_CURRENT|MCL_FUTURE) succeeded */
	ARFLEX_FLAG_SAFE_ACTIVE = 1u << 2,    /**< safe hook runs instead of update */
	ARFLEX_FLAG_RESET_REQUIRED = 1u << 3, /**< motion needs an operator RESET */
	ARFLEX_FLAG_AFFINITY = 1u << 4,       /**< CPU affinity applied */
	ARFLEX_FLAG_DMA_LATENCY = 1u << 5,    /**< /dev/cpu_dma_latency held at 0 */
	ARFLEX_FLAG_SUPERVISOR_LOST = 1u << 6, /**< supervisor pipe (fd 0) reached EOF: orphaned */
	/** D70: configure registered a re-adopt hook (arflex_component_readopt): the RUNNING half
	 *  can take a state block again (READOPT). Set before READY, kept until the process exits. */
	ARFLEX_FLAG_READOPT = 1u << 7,
};

/** Bits of config.cfg_flags (manager, before spawn). */
enum arflex_cfg_flag {
	ARFLEX_CFG_MOVES_HARDWARE = 1u << 0, /**< leaving safe mode needs an operator RESET */
	ARFLEX_CFG_NO_MLOCK = 1u << 1,       /**< do not call mlockall (tests, many instances) */
	ARFLEX_CFG_NO_DMA_LATENCY = 1u << 2, /**< do not hold /dev/cpu_dma_latency */
	/** fd 0 of the RT process is a pipe whose write end the supervisor holds for the life of
	 *  the process: EOF on it means the supervisor is gone (ABI.md 6.2). */
	ARFLEX_CFG_SUPERVISOR_PIPE = 1u << 3,
};

/** Safe-output mode, config.safe_mode; passed to the component's safe hook. */
enum arflex_safe_mode {
	ARFLEX_SAFE_HOLD = 0, /**< hold the last output */
	ARFLEX_SAFE_ZERO = 1, /**< drive outputs to zero / neutral */
};

/** Task type, config.task_type. Periodic and service tasks run a periodic loop. A sporadic
 *  task is released by new samples on its first declared input, at most once per period (the
 *  minimum inter-arrival time; samples in between are coalesced and counted in
 *  stats.missed_periods, the releases that coalesced in stats.overruns); a sporadic task that
 *  declares no input runs the periodic loop at its minimum inter-arrival (DECISIONS.md D27). */
enum arflex_task_type {
	ARFLEX_TASK_PERIODIC = 0,
	ARFLEX_TASK_SPORADIC = 1,
	ARFLEX_TASK_SERVICE = 2,
};

/** Warning kinds (index into ctl->warnings and struct arflex_task counters). */
enum arflex_warn_kind {
	ARFLEX_WARN_SCHED = 0,       /**< SCHED_FIFO refused, running SCHED_OTHER */
	ARFLEX_WARN_AFFINITY = 1,    /**< CPU affinity refused */
	ARFLEX_WARN_MLOCK = 2,       /**< mlockall refused */
	ARFLEX_WARN_DMA_LATENCY = 3, /**< /dev/cpu_dma_latency not held */
	ARFLEX_WARN_OVERRUN = 4,     /**< a cycle overran its period */
	ARFLEX_WARN_DEADLINE = 5,    /**< a cycle finished after its deadline */
	ARFLEX_WARN_SLEEP = 6,       /**< clock_nanosleep failed */
	ARFLEX_WARN_UPDATE = 7,      /**< update hook returned an error */
	ARFLEX_WARN_PARAM = 8,       /**< a parameter request was rejected */
	ARFLEX_WARN_INPUT = 9,       /**< an input read failed (retries exhausted, bad header) */
	ARFLEX_WARN_SAFE = 10,       /**< safe mode entered (heartbeat lost or reset required) */
	ARFLEX_WARN_FORGED = 11,     /**< a mailbox request with a wrong token was ignored */
	ARFLEX_WARN_HB_LOST = 12,    /**< the runtime heartbeat went stale (safe mode, D75) */
	ARFLEX_WARN_RESET = 13,      /**< safe mode for RESET_REQUIRED alone: set by the
				      *   component itself (a latched trip) or its manager (D75) */
};

/** Causes of ctl->hold (bits 0..7). Detail (bits 8..15): for SAFETY_INPUT the enum
 *  arflex_safety_verdict (arflex/safety_gate.h); input (bits 16..23): index of the input in
 *  the order the component declared them. */
enum arflex_hold_cause {
	ARFLEX_HOLD_NONE = 0,
	ARFLEX_HOLD_SAFETY_INPUT = 1,  /**< a safety input does not permit motion */
	ARFLEX_HOLD_AWAIT_COMMAND = 2, /**< stopped; after the reset, waits for a fresh command */
	ARFLEX_HOLD_REFERENCE = 3,     /**< the reference input does not meet the arm */
};
/** Detail (bits 8..15) of ARFLEX_HOLD_REFERENCE. */
enum arflex_hold_reference_detail {
	ARFLEX_HOLD_REF_NOT_MET = 0, /**< no acquired reference: too far from the arm, or not yet at
					  rest after a stop */
	ARFLEX_HOLD_REF_INVALID = 1, /**< the newest value failed validation (non-finite, out of
					  range): the last valid reference is held */
};
#define ARFLEX_HOLD_WORD(cause, detail, input) \
	((uint32_t)(cause) | ((uint32_t)(detail) & 0xffu) << 8 | ((uint32_t)(input) & 0xffu) << 16)

/* ---- statistics (seqlock) ----------------------------------------------------------- */

/** One measured quantity (wake-up latency or execution time), in ns. 16128 bytes. */
struct arflex_metric {
	uint64_t count;          /**< samples */
	uint64_t min_ns;         /**< UINT64_MAX while count == 0 */
	uint64_t max_ns;
	uint64_t sum_ns;         /**< mean = sum_ns / count */
	uint64_t sum_absdev_ns;  /**< sum of |x - running mean|; MAD ~= sum_absdev_ns / count */
	uint64_t reserved[3];
	uint64_t hist[ARFLEX_HIST_BINS + 1]; /**< 100 ns bins, last = overflow (>= 200 us) */
	uint64_t hist_pad[7];
};

/** Statistics block. Written by the RT thread only, under the seqlock @seq: the writer makes
 *  seq odd, updates, makes it even again. A reader copies the block between two equal even
 *  reads of seq. 32384 bytes. */
struct arflex_stats {
	uint64_t seq;            /**< seqlock word: odd while the writer updates */
	uint64_t cycles;         /**< completed cycles */
	uint64_t overruns;       /**< cycles whose next release was already in the past
				  *   (sporadic: releases that coalesced samples) */
	uint64_t missed_periods; /**< periods skipped by catch-up after overruns
				  *   (sporadic: samples coalesced, not run on their own) */
	uint64_t deadline_misses;/**< cycles that ended later than release + deadline */
	uint64_t update_errors;  /**< update hook returned < 0 */
	uint64_t safe_cycles;    /**< cycles run through the safe hook */
	uint64_t last_release_ns;/**< CLOCK_MONOTONIC of the last release */
	struct arflex_metric latency; /**< wake-up latency: actual wake - planned release */
	struct arflex_metric exec;    /**< execution time of the cycle's work */
};

/* ---- parameters --------------------------------------------------------------------- */

/** Parameter value type (slot.type). Values are 8 bytes: int64 for BOOL (0/1) and INT64,
 *  IEEE 754 binary64 bits for DOUBLE. */
enum arflex_param_type {
	ARFLEX_PARAM_UNUSED = 0,
	ARFLEX_PARAM_BOOL = 1,
	ARFLEX_PARAM_INT64 = 2,
	ARFLEX_PARAM_DOUBLE = 3,
};

/** slot.flags bits. */
enum arflex_param_flag {
	ARFLEX_PARAM_MUTABLE = 1u << 0, /**< may change while RUNNING */
};

/** One parameter slot, 128 bytes. Descriptor fields are written by the manager before spawn.
 *
 *  Request (one requester per slot): req_seq is even at rest; to request value v the
 *  requester stores req_seq+1 (odd), req_value = v, then req_seq+2 (even, release).
 *  Apply (RT process): when req_seq (acquire) is even and differs from applied_seq, and a
 *  re-read after loading req_value still gives the same req_seq, the value is checked
 *  (type, range, mutability); on success applied_value = v; then applied_status = 0 or
 *  -ERANGE/-EPERM/-EINVAL, and last applied_seq = req_seq (release). While RUNNING this happens
 *  on the RT thread at a cycle boundary only, so update never sees a torn or mid-cycle value.
 */
struct arflex_param_slot {
	char name[ARFLEX_NAME_SIZE]; /**< NUL-terminated, [a-z][a-z0-9_.]{0,30}; "" = unused */
	uint32_t type;               /**< enum arflex_param_type */
	uint32_t flags;              /**< enum arflex_param_flag */
	uint64_t min_bits;           /**< inclusive lower bound (same encoding as values) */
	uint64_t max_bits;           /**< inclusive upper bound */
	uint64_t default_bits;       /**< initial value; applied at attach */
	uint64_t req_seq;            /**< requester's sequence (even at rest) */
	uint64_t req_value;          /**< requested value bits */
	uint64_t applied_seq;        /**< req_seq of the last handled request (0: none yet) */
	uint64_t applied_value;      /**< value in force */
	int32_t applied_status;      /**< 0 or -errno of the last handled request */
	uint32_t reserved0;
	uint64_t reserved[3];
};

/* ---- configuration (manager, before spawn) ------------------------------------------ */

/** Timing and behaviour configuration, 64 bytes. */
struct arflex_ctl_config {
	uint64_t period_ns;       /**< cycle period (> 0) */
	uint64_t deadline_ns;     /**< relative deadline (0: = period) */
	uint64_t hb_timeout_ns;   /**< runtime heartbeat timeout (0: watchdog off) */
	uint64_t cpu_mask;        /**< bit i = CPU i allowed; 0 = no affinity */
	int32_t priority;         /**< SCHED_FIFO priority 1..99 (0: SCHED_OTHER by choice) */
	uint32_t task_type;       /**< enum arflex_task_type */
	uint32_t safe_mode;       /**< enum arflex_safe_mode */
	uint32_t cfg_flags;       /**< enum arflex_cfg_flag */
	uint32_t param_count;     /**< slots in use (the first param_count slots) */
	uint32_t reserved0;
	uint64_t orphan_hold_ns;  /**< after the supervisor is lost: hold safe outputs this long,
				   *   then exit and unlink (ABI.md 6.2); 0 = after one safe cycle */
};

/* ---- the control block -------------------------------------------------------------- */

/** The whole control block segment. Size ARFLEX_CTL_SIZE (40960 bytes = 10 pages). */
/** Count of one input's rejected values (ABI 1.2). The RT process writes both words: the name
 *  hash at configure, the count from its RT thread. */
struct arflex_input_count {
	uint32_t name_hash; /**< low 32 bits of FNV-1a 64 of the input's name (0: slot unused) */
	uint32_t rejects;   /**< values refused: damaged segment, or invalid (NaN, Inf, out of range) */
};

/** Input count slots in the control block (the template's ARFLEX_MAX_INPUTS). */
#define ARFLEX_CTL_INPUTS 16

struct arflex_ctl {
	/* header, 64 bytes at 0 */
	uint64_t magic;          /**< ARFLEX_CTL_MAGIC */
	uint16_t abi_major;      /**< ARFLEX_ABI_MAJOR */
	uint16_t abi_minor;      /**< ARFLEX_ABI_MINOR */
	uint32_t header_size;    /**< offsetof(struct arflex_ctl, stats) */
	uint64_t size;           /**< total segment size in bytes */
	uint32_t state;          /**< enum arflex_rt_state (RT process) */
	uint32_t flags;          /**< enum arflex_ctl_flag */
	int32_t pid;             /**< RT process pid (RT process, at attach; 0 before) */
	int32_t exit_status;     /**< last error of the RT half (0 or -errno), for diagnosis */
	uint64_t runtime_hb_ns;  /**< manager heartbeat, CLOCK_MONOTONIC ns */
	uint64_t rt_hb_ns;       /**< RT thread heartbeat, CLOCK_MONOTONIC ns, every cycle */
	uint32_t hold;           /**< why the component holds the arm by itself (RT process):
				      ARFLEX_HOLD_WORD(cause, detail, input); 0 = not holding */
	uint32_t reserved_hdr;
	/* config, 64 bytes at 64 */
	struct arflex_ctl_config config;
	/* warnings, 128 bytes at 128: count of each enum arflex_warn_kind (RT process) */
	uint64_t warnings[ARFLEX_WARN_KINDS];
	/* statistics at 256 */
	struct arflex_stats stats;
	/* parameter table at 32576 */
	struct arflex_param_slot params[ARFLEX_PARAM_SLOTS];
	/* rejected values per input at 40768 (ABI 1.2; RT process) */
	struct arflex_input_count inputs[ARFLEX_CTL_INPUTS];
	/* padding to ARFLEX_CTL_SIZE */
	uint8_t tail_pad[40960 - 32576 - ARFLEX_PARAM_SLOTS * 128 - ARFLEX_CTL_INPUTS * 8];
};

#define ARFLEX_CTL_SIZE 40960u

ARFLEX_STATIC_ASSERT(sizeof(struct arflex_metric) == 16128, "metric size");
ARFLEX_STATIC_ASSERT(sizeof(struct arflex_stats) == 32320, "stats size");
ARFLEX_STATIC_ASSERT(sizeof(struct arflex_param_slot) == 128, "param slot size");
ARFLEX_STATIC_ASSERT(sizeof(struct arflex_ctl_config) == 64, "config size");
ARFLEX_STATIC_ASSERT(offsetof(struct arflex_ctl_config, orphan_hold_ns) == 56, "orphan_hold");
ARFLEX_STATIC_ASSERT(offsetof(struct arflex_ctl, state) == 24, "ctl.state");
ARFLEX_STATIC_ASSERT(offsetof(struct arflex_ctl, runtime_hb_ns) == 40, "ctl.runtime_hb");
ARFLEX_STATIC_ASSERT(offsetof(struct arflex_ctl, rt_hb_ns) == 48, "ctl.rt_hb");
ARFLEX_STATIC_ASSERT(offsetof(struct arflex_ctl, hold) == 56, "ctl.hold");
ARFLEX_STATIC_ASSERT(offsetof(struct arflex_ctl, config) == 64, "ctl.config");
ARFLEX_STATIC_ASSERT(offsetof(struct arflex_ctl, warnings) == 128, "ctl.warnings");
ARFLEX_STATIC_ASSERT(offsetof(struct arflex_ctl, stats) == 256, "ctl.stats");
ARFLEX_STATIC_ASSERT(offsetof(struct arflex_ctl, params) == 32576, "ctl.params");
ARFLEX_STATIC_ASSERT(offsetof(struct arflex_ctl, inputs) == 40768, "ctl.inputs");
ARFLEX_STATIC_ASSERT(sizeof(struct arflex_ctl) == ARFLEX_CTL_SIZE, "ctl size");

/* ---- API ---------------------------------------------------------------------------- */

/** Checks a control block name component: [a-z0-9-]{1,40}. Predicate. */
ARFLEX_API bool arflex_ctl_id_valid(const char *id);

/**
 * Formats "/arflex.<rid>.<inst>.<channel>" into @buf (@size bytes, ARFLEX_OBJ_NAME_SIZE is
 * always enough for valid ids, channels up to 40 chars). Returns 0, -EINVAL for an invalid
 * rid or instance (names it on stderr is NOT done: the caller reports), -ENAMETOOLONG.
 */
ARFLEX_API int arflex_ctl_obj_name(char *buf, size_t size, const char *rid, const char *inst,
				   const char *channel);

/**
 * Initialises a freshly created, zeroed control block in memory (manager side): header,
 * @config, parameter descriptors from @params (@nparams <= ARFLEX_PARAM_SLOTS, name/type/
 * flags/min/max/default set; other fields ignored), applied values = defaults, stats min
 * fields = UINT64_MAX. Returns 0, -EINVAL if a parameter is malformed (bad name, duplicate,
 * default out of range, unknown type), -E2BIG if too many.
 */
ARFLEX_API int arflex_ctl_format(struct arflex_ctl *ctl, const struct arflex_ctl_config *config,
				 const struct arflex_param_slot *params, unsigned nparams);

/** Checks magic, ABI major, minor >= ours and size of a mapped control block of @maplen
 *  bytes. Returns 0, -EPROTO (bad magic or major), -EPROTONOSUPPORT (older minor),
 *  -EMSGSIZE (size mismatch). */
ARFLEX_API int arflex_ctl_check(const struct arflex_ctl *ctl, size_t maplen);

/** Index of the parameter named @name, or -ENOENT. */
ARFLEX_API int arflex_ctl_param_find(const struct arflex_ctl *ctl, const char *name);

/**
 * Validates @bits for slot @idx: type, range; and mutability when @running. Returns 0,
 * -EINVAL (unused slot, bool not 0/1, NaN), -ERANGE, -EPERM (immutable while running).
 */
ARFLEX_API int arflex_ctl_param_validate(const struct arflex_ctl *ctl, unsigned idx,
					 uint64_t bits, bool running);

/** Requester side: posts a request of @bits for slot @idx (protocol above). Returns the new
 *  even req_seq the apply side will echo in applied_seq. The caller must be the only
 *  requester of that slot. */
ARFLEX_API uint64_t arflex_ctl_param_request(struct arflex_ctl *ctl, unsigned idx,
					     uint64_t bits);

/** Apply side: handles the pending request of slot @idx, if any. Returns 1 if a request was
 *  handled (see applied_status), 0 if none was pending or it was mid-write. Never blocks. */
ARFLEX_API int arflex_ctl_param_apply(struct arflex_ctl *ctl, unsigned idx, bool running);

/** Apply side: arflex_ctl_param_apply() on every slot in use. Returns the number handled. */
ARFLEX_API int arflex_ctl_param_apply_all(struct arflex_ctl *ctl, bool running);

/** Value in force of slot @idx (atomic load). */
ARFLEX_API uint64_t arflex_ctl_param_value(const struct arflex_ctl *ctl, unsigned idx);

/** Bits of a double, and back. */
ARFLEX_API uint64_t arflex_f64_bits(double v);
ARFLEX_API double arflex_bits_f64(uint64_t bits);

/** Reader side of the statistics seqlock: copies a consistent snapshot into @out. Retries up
 *  to 1000 times. Returns 0 or -EAGAIN. */
ARFLEX_API int arflex_ctl_stats_read(const struct arflex_ctl *ctl, struct arflex_stats *out);

/** Percentile @p (0 < p < 100, e.g. 99.9) of a metric from its histogram, in ns (upper edge of
 *  the bin; the max for the overflow bin). Returns 0 when empty. */
ARFLEX_API uint64_t arflex_metric_percentile(const struct arflex_metric *m, double p);

/**
 * Windowed judgement of the runtime heartbeat (ABI.md 6.1), the state of one RT thread.
 * Zero it before the first cycle of a run.
 */
struct arflex_hb_window {
	uint64_t last_hb;    /**< runtime_hb_ns seen at the previous judgement */
	uint64_t last_now;   /**< time of the previous judgement; 0 = none yet */
	uint64_t silence_ns; /**< cycling time of the RT thread since runtime_hb_ns last changed */
};

/**
 * One judgement per cycle of the RT thread at time @now, the runtime heartbeat reading @hb:
 * returns true when the runtime is silent beyond @timeout_ns (0: never). Silence is counted
 * only over time the RT thread itself was cycling: each step adds at most 2 * @period_ns, so a
 * stall of the whole machine (the RT thread late too) does not count as the runtime's
 * silence, while a runtime that stops writing is caught after @timeout_ns of cycles (plus a
 * period). A changed @hb resets the silence. The first judgement counts the age of @hb
 * (now - hb) as silence. Pure: no shared memory, no clock; RT safe.
 */
ARFLEX_API bool arflex_hb_judge(struct arflex_hb_window *w, uint64_t hb, uint64_t now,
				uint64_t period_ns, uint64_t timeout_ns);

/** Atomic accessors for the shared words (acquire loads, release stores). */
ARFLEX_API uint32_t arflex_ctl_state(const struct arflex_ctl *ctl);
ARFLEX_API uint32_t arflex_ctl_flags(const struct arflex_ctl *ctl);
ARFLEX_API uint32_t arflex_ctl_hold(const struct arflex_ctl *ctl);
ARFLEX_API void arflex_ctl_set_runtime_hb(struct arflex_ctl *ctl, uint64_t now_ns);

#ifdef __cplusplus
}
#endif
#endif /* ARFLEX_CONTROL_H */
