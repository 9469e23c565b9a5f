/* The periodic loop (cyclictest's shape) with preallocated statistics. */
#include "arflex/task.h"

#include <errno.h>
#include <fcntl.h>
#include <sched.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#define LOAD(p) __atomic_load_n((p), __ATOMIC_ACQUIRE)
#define STORE(p, v) __atomic_store_n((p), (v), __ATOMIC_RELEASE)

enum { T_IDLE, T_STARTING, T_RUNNING, T_DONE };

static const char *const warn_names[ARFLEX_WARN_KINDS] = {
	[ARFLEX_WARN_SCHED] = "SCHED_FIFO refused, running SCHED_OTHER",
	[ARFLEX_WARN_AFFINITY] = "CPU affinity refused",
	[ARFLEX_WARN_MLOCK] = "mlockall refused, memory may page",
	[ARFLEX_WARN_DMA_LATENCY] = "/dev/cpu_dma_latency not held",
	[ARFLEX_WARN_OVERRUN] = "cycle overran its period",
	[ARFLEX_WARN_DEADLINE] = "cycle missed its deadline",
	[ARFLEX_WARN_SLEEP] = "clock_nanosleep failed",
	[ARFLEX_WARN_UPDATE] = "update hook returned an error",
	[ARFLEX_WARN_PARAM] = "parameter request rejected",
	[ARFLEX_WARN_INPUT] = "input read failed",
	[ARFLEX_WARN_SAFE] = "safe mode entered",
	[ARFLEX_WARN_FORGED] = "mailbox request with a wrong token ignored",
	[ARFLEX_WARN_HB_LOST] = "runtime heartbeat lost (unchanged for longer than its timeout): safe mode",
	[ARFLEX_WARN_RESET] = "operator reset required (latched by the component itself, e.g. a trip, or set "
			      "by its manager), not a lost heartbeat: safe mode",
};

const char *arflex_warn_name(unsigned kind)
{
	if (kind >= ARFLEX_WARN_KINDS || !warn_names[kind])
		return "unknown warning";
	return warn_names[kind];
}

static uint64_t *warns(struct arflex_task *t)
{
	return t->o.warnings ? t->o.warnings : t->own_warnings;
}

static void warn(struct arflex_task *t, enum arflex_warn_kind k)
{
	__atomic_add_fetch(&warns(t)[k], 1, __ATOMIC_RELAXED);
}

static void set_flag(struct arflex_task *t, uint32_t f)
{
	__atomic_or_fetch(t->o.flags ? t->o.flags : &t->own_flags, f, __ATOMIC_RELEASE);
}

void arflex_metric_reset(struct arflex_metric *m)
{
	memset(m, 0, sizeof(*m));
	m->min_ns = UINT64_MAX;
}

void arflex_metric_add(struct arflex_metric *m, uint64_t ns)
{
	uint64_t bin = ns / ARFLEX_HIST_BIN_NS;

	if (m->count) {
		uint64_t mean = m->sum_ns / m->count;

		m->sum_absdev_ns += ns > mean ? ns - mean : mean - ns;
	}
	m->count++;
	m->sum_ns += ns;
	if (ns < m->min_ns)
		m->min_ns = ns;
	if (ns > m->max_ns)
		m->max_ns = ns;
	m->hist[bin < ARFLEX_HIST_BINS ? bin : ARFLEX_HIST_BINS]++;
}

struct arflex_stats *arflex_task_stats(struct arflex_task *t)
{
	return t->o.stats ? t->o.stats : &t->own_stats;
}

void arflex_task_reset_stats(struct arflex_task *t)
{
	struct arflex_stats *s = arflex_task_stats(t);
	uint64_t seq = LOAD(&s->seq);

	STORE(&s->seq, seq + 1);
	__atomic_thread_fence(__ATOMIC_RELEASE);
	memset((char *)s + sizeof(s->seq), 0, sizeof(*s) - sizeof(s->seq));
	arflex_metric_reset(&s->latency);
	arflex_metric_reset(&s->exec);
	STORE(&s->seq, seq + 2);
}

int arflex_task_init(struct arflex_task *t, const struct arflex_task_opts *o)
{
	if (!o || !o->cycle || o->period_ns == 0 || o->priority < 0 || o->priority > 99 ||
	    o->deadline_ns > o->period_ns)
		return -EINVAL;
	memset(t, 0, sizeof(*t));
	t->o = *o;
	if (!t->o.deadline_ns)
		t->o.deadline_ns = t->o.period_ns;
	if (t->o.poll && !t->o.poll_ns)
		t->o.poll_ns = ARFLEX_TASK_POLL_NS(t->o.period_ns);
	t->dma_fd = -1;
	pthread_mutex_init(&t->lock, NULL);
	pthread_cond_init(&t->cond, NULL);
	arflex_task_reset_stats(t);
	return 0;
}

static void setup_rt(struct arflex_task *t)
{
	int r;

	/* Memory first, while the thread is still SCHED_OTHER and not yet pinned: mlockall faults
	 * in the whole process (its libraries, a model, the heap), milliseconds for a large half.
	 * Done at SCHED_FIFO on the RT CPU it held off every task of its priority there until it
	 * returned: a half started beside sim-robot (both at 80) cost sim-robot its releases. */
	if (!t->o.no_mlock) {
		if (arflex_sys_mlockall(MCL_CURRENT | MCL_FUTURE) == 0)
			set_flag(t, ARFLEX_FLAG_MLOCKALL);
		else
			warn(t, ARFLEX_WARN_MLOCK);
	}
	if (!t->o.no_dma_latency) {
		int fd = arflex_sys_open("/dev/cpu_dma_latency", O_RDWR | O_CLOEXEC, 0);
		int32_t zero = 0;

		if (fd >= 0 && arflex_sys_write_all(fd, &zero, sizeof(zero)) == 0) {
			t->dma_fd = fd;
			set_flag(t, ARFLEX_FLAG_DMA_LATENCY);
		} else {
			if (fd >= 0)
				arflex_sys_close(fd);
			warn(t, ARFLEX_WARN_DMA_LATENCY);
		}
	}
	if (t->o.cpu_mask) {
		if (arflex_sys_set_affinity(t->o.cpu_mask) == 0)
			set_flag(t, ARFLEX_FLAG_AFFINITY);
		else
			warn(t, ARFLEX_WARN_AFFINITY);
	}
	if (t->o.priority > 0) {
		r = arflex_sys_set_sched(SCHED_FIFO, t->o.priority);
		if (r == 0) {
			set_flag(t, ARFLEX_FLAG_SCHED_FIFO);
		} else {
			t->sched_err = r;
			warn(t, ARFLEX_WARN_SCHED);
		}
	}
}

static void release_rt(struct arflex_task *t)
{
	if (t->dma_fd >= 0) {
		arflex_sys_close(t->dma_fd);
		t->dma_fd = -1;
		__atomic_and_fetch(t->o.flags ? t->o.flags : &t->own_flags,
				   ~(uint32_t)ARFLEX_FLAG_DMA_LATENCY, __ATOMIC_RELEASE);
	}
}

static void set_state(struct arflex_task *t, int st)
{
	pthread_mutex_lock(&t->lock);
	STORE(&t->state, st);
	pthread_cond_broadcast(&t->cond);
	pthread_mutex_unlock(&t->lock);
}

static void loop(struct arflex_task *t)
{
	struct arflex_stats *s = arflex_task_stats(t);
	const uint64_t period = t->o.period_ns;
	/* the first release is the start itself, then one every period: a component installed
	 * into a running cell runs its first cycle when it is started, not a period later (at
	 * 10 ms, that period was most of install-to-first-cycle; D44) */
	uint64_t next = arflex_sys_now_ns();

	while (!LOAD(&t->stop)) {
		uint64_t wake, end, seq;
		int r;

		if (arflex_sys_sleep_until(next))
			warn(t, ARFLEX_WARN_SLEEP);
		wake = arflex_sys_now_ns();
		r = t->o.cycle(t->o.arg, next);
		end = arflex_sys_now_ns();

		seq = s->seq;
		STORE(&s->seq, seq + 1);
		__atomic_thread_fence(__ATOMIC_RELEASE);
		s->cycles++;
		s->last_release_ns = next;
		arflex_metric_add(&s->latency, wake > next ? wake - next : 0);
		arflex_metric_add(&s->exec, end - wake);
		if (end > next + t->o.deadline_ns) {
			s->deadline_misses++;
			warn(t, ARFLEX_WARN_DEADLINE);
		}
		if (r < 0) {
			s->update_errors++;
			warn(t, ARFLEX_WARN_UPDATE);
		}
		next += period;
		if (next <= end) {
			uint64_t missed = (end - next) / period + 1;

			next += missed * period;
			s->overruns++;
			s->missed_periods += missed;
			warn(t, ARFLEX_WARN_OVERRUN);
		}
		STORE(&s->seq, seq + 2);

		if (r > 0 || (t->o.max_cycles && s->cycles >= t->o.max_cycles))
			break;
	}
}

/* Sporadic mode: waits for the earliest release @earliest, then polls every poll_ns (absolute
 * ticks) until poll reports events. Returns false when stopped first; else *@release is the
 * tick at which the events were seen, *@wake the actual time of that poll. */
static bool wait_release(struct arflex_task *t, uint64_t earliest, uint64_t *release,
			 uint64_t *wake, uint64_t *events)
{
	const uint64_t poll = t->o.poll_ns;
	uint64_t tick = earliest;

	if (arflex_sys_sleep_until(tick))
		warn(t, ARFLEX_WARN_SLEEP);
	for (;;) {
		uint64_t now;

		if (LOAD(&t->stop))
			return false;
		now = arflex_sys_now_ns();
		*events = 0;
		if (t->o.poll(t->o.arg, now, events) > 0) {
			if (*events == 0)
				*events = 1;
			*release = tick;
			*wake = now;
			return true;
		}
		tick += poll;
		if (tick <= now) /* woke late: the next tick still ahead, no burst of polls */
			tick += ((now - tick) / poll + 1) * poll;
		if (arflex_sys_sleep_until(tick))
			warn(t, ARFLEX_WARN_SLEEP);
	}
}

static void sporadic_loop(struct arflex_task *t)
{
	struct arflex_stats *s = arflex_task_stats(t);
	const uint64_t period = t->o.period_ns;
	uint64_t earliest = arflex_sys_now_ns();

	for (;;) {
		uint64_t release, wake, end, seq, events;
		int r;

		if (!wait_release(t, earliest, &release, &wake, &events))
			break;
		r = t->o.cycle(t->o.arg, release);
		end = arflex_sys_now_ns();

		seq = s->seq;
		STORE(&s->seq, seq + 1);
		__atomic_thread_fence(__ATOMIC_RELEASE);
		s->cycles++;
		s->last_release_ns = release;
		arflex_metric_add(&s->latency, wake > release ? wake - release : 0);
		arflex_metric_add(&s->exec, end - wake);
		if (end > release + t->o.deadline_ns) {
			s->deadline_misses++;
			warn(t, ARFLEX_WARN_DEADLINE);
		}
		if (r < 0) {
			s->update_errors++;
			warn(t, ARFLEX_WARN_UPDATE);
		}
		if (events > 1) { /* the input outran the minimum inter-arrival: coalesced */
			s->overruns++;
			s->missed_periods += events - 1;
			warn(t, ARFLEX_WARN_OVERRUN);
		}
		STORE(&s->seq, seq + 2);

		if (r > 0 || (t->o.max_cycles && s->cycles >= t->o.max_cycles))
			break;
		/* minimum inter-arrival; a cycle that ran past it is released no earlier than
		 * its end (the deadline of what comes next counts from when it can be seen) */
		earliest = release + period;
		if (earliest < end)
			earliest = end;
	}
}

/* Body shared by the thread and arflex_task_run. */
static int body(struct arflex_task *t)
{
	int r = 0;

	setup_rt(t);
	if (t->o.on_start) {
		r = t->o.on_start(t->o.arg);
		if (r < 0) {
			t->start_err = r;
			release_rt(t);
			set_state(t, T_DONE);
			return r;
		}
	}
	set_state(t, T_RUNNING);
	if (t->o.poll)
		sporadic_loop(t);
	else
		loop(t);
	if (t->o.on_stop)
		t->o.on_stop(t->o.arg);
	release_rt(t);
	set_state(t, T_DONE);
	return 0;
}

static void *thread_main(void *arg)
{
	body(arg);
	return NULL;
}

int arflex_task_start(struct arflex_task *t)
{
	int r;

	if (t->thread_live || LOAD(&t->state) == T_RUNNING)
		return -EALREADY;
	STORE(&t->stop, 0);
	t->start_err = 0;
	STORE(&t->state, T_STARTING);
	r = arflex_sys_thread_create(&t->thread, NULL, thread_main, t);
	if (r) {
		STORE(&t->state, T_IDLE);
		return r;
	}
	t->thread_live = true;
	pthread_mutex_lock(&t->lock);
	while (LOAD(&t->state) == T_STARTING)
		pthread_cond_wait(&t->cond, &t->lock);
	pthread_mutex_unlock(&t->lock);
	if (t->start_err) {
		arflex_sys_thread_join(t->thread, NULL);
		t->thread_live = false;
		STORE(&t->state, T_IDLE);
		return t->start_err;
	}
	return 0;
}

int arflex_task_run(struct arflex_task *t)
{
	STORE(&t->stop, 0);
	STORE(&t->state, T_STARTING);
	return body(t);
}

void arflex_task_request_stop(struct arflex_task *t)
{
	STORE(&t->stop, 1);
}

bool arflex_task_running(const struct arflex_task *t)
{
	return LOAD(&t->state) == T_RUNNING;
}

int arflex_task_stop(struct arflex_task *t)
{
	arflex_task_request_stop(t);
	if (t->thread_live) {
		arflex_sys_thread_join(t->thread, NULL);
		t->thread_live = false;
	}
	STORE(&t->state, T_IDLE);
	return 0;
}

void arflex_task_deinit(struct arflex_task *t)
{
	arflex_task_stop(t);
	pthread_cond_destroy(&t->cond);
	pthread_mutex_destroy(&t->lock);
}

uint64_t arflex_task_warnings(const struct arflex_task *t, enum arflex_warn_kind k)
{
	const uint64_t *w = t->o.warnings ? t->o.warnings : t->own_warnings;

	return (unsigned)k < ARFLEX_WARN_KINDS ? __atomic_load_n(&w[k], __ATOMIC_RELAXED) : 0;
}

uint32_t arflex_task_flags(const struct arflex_task *t)
{
	return LOAD(t->o.flags ? t->o.flags : &t->own_flags);
}

int arflex_task_report(struct arflex_task *t, FILE *out)
{
	int lines = 0;

	for (unsigned k = 0; k < ARFLEX_WARN_KINDS; k++) {
		uint64_t c = arflex_task_warnings(t, k);

		if (c && !t->reported[k]) {
			if (k == ARFLEX_WARN_SCHED)
				fprintf(out, "arflex: %s: warning: %s (priority %d: %s); timing is "
					"not real-time\n", t->o.name ? t->o.name : "task",
					arflex_warn_name(k), t->o.priority, strerror(-t->sched_err));
			else
				fprintf(out, "arflex: %s: warning: %s\n",
					t->o.name ? t->o.name : "task", arflex_warn_name(k));
			lines++;
		}
		t->reported[k] = c;
	}
	if (lines) {
		fflush(out);
		clearerr(out); /* a pipe nobody reads (EPIPE) or a full one (EAGAIN): dropped */
	}
	return lines;
}
