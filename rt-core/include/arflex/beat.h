/*
 * arflex/beat.h - the runtime heartbeat's native writer, loaded into the manager's process (the
 * DRCR's JVM, through JNA). One thread, at a low SCHED_FIFO priority, writes runtime_hb_ns into
 * every registered control block each period, as long as the manager's own code said it is
 * alive (arflex_beat_java_alive) within a grace time. So:
 *   - the manager process stopped (SIGSTOP) or dead: the thread stops too (or the supervisor
 *     pipe reaches EOF); RT halves go to safe mode after their heartbeat timeout, as before;
 *   - the manager's code stalled for less than the grace (a garbage collection, a safepoint
 *     that a busy machine delays, a lock held by a preempted thread): the heartbeat goes on and
 *     no moving component latches a reset for it;
 *   - stalled for longer (a deadlock, a runaway collection): the thread withholds the heartbeat
 *     and the RT halves go to safe mode within grace + their timeout.
 * See docs/DECISIONS.md D17. One writer per process (global state); every function is
 * thread-safe. Not for RT halves.
 */
#ifndef ARFLEX_BEAT_H
#define ARFLEX_BEAT_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define ARFLEX_BEAT_API __attribute__((visibility("default")))

/** Most control blocks one writer serves. */
#define ARFLEX_BEAT_SLOTS 512

struct arflex_beat_stats {
	uint64_t rounds;              /**< rounds run since start */
	uint64_t withheld;            /**< rounds that wrote nothing: the manager silent > grace */
	uint64_t bridged;             /**< manager silences longer than 2 periods that ended within the grace */
	uint64_t max_silence_ns;      /**< longest manager silence seen (between alive calls) */
	uint64_t last_silence_ns;     /**< the manager's silence at the last round */
	uint32_t registered;          /**< control blocks registered now */
	int32_t fifo;                 /**< SCHED_FIFO priority of the thread, 0 if SCHED_OTHER */
	uint64_t max_gap_ns;          /**< the writer's own longest time between two rounds (D75) */
	uint64_t last_round_ns;       /**< CLOCK_MONOTONIC of its last round, 0 before the first */
};

/**
 * Starts the writer thread: every @period_ns, while the manager said it is alive within
 * @grace_ns, runtime_hb_ns of each registered block := CLOCK_MONOTONIC now. @fifo_priority 0
 * asks for SCHED_OTHER. Returns 0 (SCHED_FIFO as asked), a positive errno when SCHED_FIFO was
 * refused and the thread runs SCHED_OTHER, or a negative errno (-EALREADY: running; -EINVAL:
 * period 0 or grace < period; thread creation failed). Starting clears every registration.
 */
ARFLEX_BEAT_API int arflex_beat_start(uint64_t period_ns, uint64_t grace_ns, int fifo_priority);

/** Stops and joins the writer thread (no-op when not running). Registrations are dropped. */
ARFLEX_BEAT_API void arflex_beat_stop(void);

/** The manager is alive now. Called from the manager's own periodic heartbeat round. */
ARFLEX_BEAT_API void arflex_beat_java_alive(void);

/**
 * Registers a mapped control block (struct arflex_ctl *). Returns 0, -EINVAL (NULL),
 * -EEXIST (already registered) or -ENOSPC (ARFLEX_BEAT_SLOTS in use).
 */
ARFLEX_BEAT_API int arflex_beat_add(void *ctl);

/**
 * Unregisters @ctl; on return 0 the writer no longer touches it (a round in progress has
 * ended), so the caller may unmap it. Returns 0, -ENOENT (not registered) or -ETIMEDOUT (a
 * round did not end within 1 s; the block must not be unmapped).
 */
ARFLEX_BEAT_API int arflex_beat_remove(void *ctl);

/** A snapshot of the counters. */
ARFLEX_BEAT_API void arflex_beat_stats(struct arflex_beat_stats *out);

#ifdef __cplusplus
}
#endif
#endif /* ARFLEX_BEAT_H */
