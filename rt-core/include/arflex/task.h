/*
 * arflex/task.h - the periodic loop of an RT half, shaped like cyclictest.
 *
 * arflex_task_init() prepares everything (statistics storage is caller-owned or inside the
 * struct; nothing is allocated later). arflex_task_start() creates the RT thread, which:
 * pins itself to opts.cpu_mask, sets SCHED_FIFO at opts.priority (when refused: one warning
 * and SCHED_OTHER), mlockall() (unless disabled), holds /dev/cpu_dma_latency at 0 if it can
 * open it, calls opts.on_start, then loops: absolute clock_nanosleep(CLOCK_MONOTONIC) to the
 * next release, record wake-up latency, call opts.cycle, record execution time, release +=
 * period; if the next release is already past (overrun) count it and skip whole periods to
 * catch up. After the loop it calls opts.on_stop and releases what it held.
 *
 * Sporadic mode (opts.poll set): the loop is released by events instead of the clock. After
 * each cycle it sleeps until the earliest next release (last release + period: the period is
 * the minimum inter-arrival time), then calls opts.poll at absolute ticks every opts.poll_ns;
 * the first tick at which poll reports new events is the release (the event's arrival as the
 * RT thread sees it: latency = actual wake - that tick, the deadline counts from it). Events
 * that came in while the task waited for its minimum inter-arrival are coalesced into one
 * release: poll reports how many; the extra ones count as stats.missed_periods, and a release
 * that coalesced counts as one stats.overrun (DECISIONS.md D27).
 *
 * The RT thread never blocks (besides its sleep), allocates or prints after start: problems
 * are counted per enum arflex_warn_kind; a non-RT thread calls arflex_task_report() to print
 * the first of each kind once.
 */
#ifndef ARFLEX_TASK_H
#define ARFLEX_TASK_H

#include <pthread.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#include "arflex/control.h"
#include "arflex/sys.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Cycle callback: called once per period on the RT thread with the planned release time.
 *  Return 0 to continue, > 0 to stop the loop normally, < 0 to count an error and continue. */
typedef int (*arflex_task_cycle_fn)(void *arg, uint64_t release_ns);
/** Start/stop callbacks on the RT thread (optional). on_start returning < 0 aborts the task
 *  (arflex_task_wait_started reports that error). */
typedef int (*arflex_task_hook_fn)(void *arg);
/** Sporadic release test, on the RT thread at every poll tick @now_ns (between cycles: a
 *  cycle boundary). Returns > 0 to release a cycle now, with *@events set to the number of
 *  events it covers (>= 1; more than 1 means events were coalesced); 0 to keep waiting. Must
 *  not block. */
typedef int (*arflex_task_poll_fn)(void *arg, uint64_t now_ns, uint64_t *events);

/** Options of a task. */
struct arflex_task_opts {
	uint64_t period_ns;          /**< > 0 */
	uint64_t deadline_ns;        /**< 0: = period */
	int priority;                /**< SCHED_FIFO priority 1..99; 0: SCHED_OTHER */
	uint64_t cpu_mask;           /**< 0: no affinity */
	bool no_mlock;               /**< skip mlockall */
	bool no_dma_latency;         /**< skip /dev/cpu_dma_latency */
	uint64_t max_cycles;         /**< stop after this many cycles; 0: until stopped */
	arflex_task_cycle_fn cycle;  /**< required */
	arflex_task_hook_fn on_start;/**< optional */
	arflex_task_hook_fn on_stop; /**< optional; called even if a cycle asked to stop */
	arflex_task_poll_fn poll;    /**< optional: sporadic mode (see above); NULL: periodic */
	uint64_t poll_ns;            /**< poll interval in sporadic mode; 0: derived from the
				      *   period, ARFLEX_TASK_POLL_NS(period) */
	void *arg;                   /**< passed to the callbacks */
	struct arflex_stats *stats;  /**< where to record (e.g. &ctl->stats); NULL: internal */
	uint64_t *warnings;          /**< ARFLEX_WARN_KINDS counters (e.g. ctl->warnings);
				      *   NULL: internal */
	uint32_t *flags;             /**< where to publish ARFLEX_FLAG_SCHED_FIFO etc. (atomic
				      *   or); NULL: internal */
	const char *name;            /**< for reports; may be NULL */
};

/** Default poll interval of a sporadic task: a tenth of its minimum inter-arrival time, kept
 *  within 50 us .. 1 ms (a release is seen at most that late; polling costs a wake-up). */
#define ARFLEX_TASK_POLL_NS(period_ns)                                                  \
	((period_ns) / 10 < 50000u ? 50000u : (period_ns) / 10 > 1000000u ? 1000000u \
									    : (period_ns) / 10)

/** A periodic (or sporadic) task. Caller-owned storage; fields are private. */
struct arflex_task {
	struct arflex_task_opts o;
	struct arflex_stats own_stats;
	uint64_t own_warnings[ARFLEX_WARN_KINDS];
	uint32_t own_flags;
	uint64_t reported[ARFLEX_WARN_KINDS]; /**< reporter: counts already reported */
	int sched_err;                        /**< detail for reports */
	int start_err;
	int state;                            /**< 0 idle, 1 starting, 2 running, 3 done */
	int stop;                             /**< atomic stop request */
	int dma_fd;
	pthread_t thread;
	bool thread_live;
	pthread_mutex_t lock;                 /**< start handshake only (not on the hot path) */
	pthread_cond_t cond;
};

/** Initialises @t with @o (copied). Resets the statistics. Returns 0 or -EINVAL (period 0,
 *  no cycle, priority out of 0..99, deadline > period). */
ARFLEX_API int arflex_task_init(struct arflex_task *t, const struct arflex_task_opts *o);

/** Resets the statistics (not while running). */
ARFLEX_API void arflex_task_reset_stats(struct arflex_task *t);

/** Starts the RT thread and waits until it is about to enter its loop (on_start done).
 *  Returns 0, the on_start error, or -errno of thread creation. */
ARFLEX_API int arflex_task_start(struct arflex_task *t);

/** Runs the loop in the calling thread (no thread created); returns when stopped or
 *  max_cycles reached: 0, or the on_start error. */
ARFLEX_API int arflex_task_run(struct arflex_task *t);

/** Asks the loop to stop after the current cycle. Async-signal safe, any thread. */
ARFLEX_API void arflex_task_request_stop(struct arflex_task *t);

/** True while the loop runs (started and not finished). */
ARFLEX_API bool arflex_task_running(const struct arflex_task *t);

/** Requests stop and joins the RT thread started by arflex_task_start. Returns 0. */
ARFLEX_API int arflex_task_stop(struct arflex_task *t);

/** Stops if needed and releases everything. */
ARFLEX_API void arflex_task_deinit(struct arflex_task *t);

/** The statistics storage in use (opts.stats or the internal block). */
ARFLEX_API struct arflex_stats *arflex_task_stats(struct arflex_task *t);

/** Warning counter of @kind. */
ARFLEX_API uint64_t arflex_task_warnings(const struct arflex_task *t, enum arflex_warn_kind k);

/** Flags published so far (ARFLEX_FLAG_SCHED_FIFO, _MLOCKALL, _AFFINITY, _DMA_LATENCY). */
ARFLEX_API uint32_t arflex_task_flags(const struct arflex_task *t);

/** Non-RT thread: prints to @out one line for each warning kind whose counter became
 *  non-zero since the last call (first occurrence of each kind only). Returns the number of
 *  lines printed. */
ARFLEX_API int arflex_task_report(struct arflex_task *t, FILE *out);

/** Records one sample into a metric (used by the loop; exposed for the baseline task and
 *  tests). Not synchronised: call under the stats seqlock writer. */
ARFLEX_API void arflex_metric_add(struct arflex_metric *m, uint64_t ns);

/** Resets a metric to empty (min = UINT64_MAX). */
ARFLEX_API void arflex_metric_reset(struct arflex_metric *m);

/** Name of a warning kind. */
ARFLEX_API const char *arflex_warn_name(unsigned kind);

#ifdef __cplusplus
}
#endif
#endif /* ARFLEX_TASK_H */
