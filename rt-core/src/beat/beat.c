/* The runtime heartbeat's native writer (arflex/beat.h, DECISIONS.md D17). */
#define _GNU_SOURCE
#include "arflex/beat.h"

#include <errno.h>
#include <pthread.h>
#include <sched.h>
#include <signal.h>
#include <stdbool.h>
#include <string.h>
#include <time.h>

#include "arflex/control.h"

#define LOAD(p) __atomic_load_n((p), __ATOMIC_ACQUIRE)
#define STORE(p, v) __atomic_store_n((p), (v), __ATOMIC_RELEASE)
#define REMOVE_WAIT_NS 1000000000ull

static void *slots[ARFLEX_BEAT_SLOTS];
static uint64_t round_seq; /* odd while a round reads the slots */
static uint64_t alive_ns;  /* the manager's last alive call */
static bool stopping;
static uint64_t period, grace;
static struct arflex_beat_stats st; /* written by the thread (and start); read atomically */

static pthread_mutex_t life = PTHREAD_MUTEX_INITIALIZER; /* start/stop only, never the thread */
static pthread_t thread;
static bool running;

static uint64_t now_ns(void)
{
	struct timespec ts;

	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (uint64_t)ts.tv_sec * 1000000000ull + (uint64_t)ts.tv_nsec;
}

static struct timespec to_ts(uint64_t ns)
{
	return (struct timespec){ .tv_sec = (time_t)(ns / 1000000000ull),
				  .tv_nsec = (long)(ns % 1000000000ull) };
}

/* One round at @now: write the heartbeat into every block, or withhold it. */
static void beat_round(uint64_t now, uint64_t *seen_alive)
{
	uint64_t alive = LOAD(&alive_ns), silence = now > alive ? now - alive : 0;
	uint64_t last = LOAD(&st.last_round_ns);

	/* D75: the writer's own lateness, told apart from the manager's silence */
	if (last && now > last && now - last > LOAD(&st.max_gap_ns))
		STORE(&st.max_gap_ns, now - last);
	STORE(&st.last_round_ns, now);

	if (alive != *seen_alive) {
		uint64_t gap = alive - *seen_alive;

		if (gap > 2 * period && gap <= grace + period)
			__atomic_add_fetch(&st.bridged, 1, __ATOMIC_RELAXED);
		if (gap > LOAD(&st.max_silence_ns))
			STORE(&st.max_silence_ns, gap);
		*seen_alive = alive;
	}
	if (silence > LOAD(&st.max_silence_ns))
		STORE(&st.max_silence_ns, silence);
	STORE(&st.last_silence_ns, silence);
	__atomic_add_fetch(&round_seq, 1, __ATOMIC_SEQ_CST);
	if (silence <= grace) {
		for (unsigned i = 0; i < ARFLEX_BEAT_SLOTS; i++) {
			struct arflex_ctl *c = __atomic_load_n(&slots[i], __ATOMIC_SEQ_CST);

			if (c)
				STORE(&c->runtime_hb_ns, now);
		}
	} else {
		__atomic_add_fetch(&st.withheld, 1, __ATOMIC_RELAXED);
	}
	__atomic_add_fetch(&round_seq, 1, __ATOMIC_SEQ_CST);
	__atomic_add_fetch(&st.rounds, 1, __ATOMIC_RELAXED);
}

static void *beat_main(void *arg)
{
	uint64_t next = now_ns(), seen = LOAD(&alive_ns);

	(void)arg;
	pthread_setname_np(pthread_self(), "arflex-beat");
	while (!LOAD(&stopping)) {
		uint64_t now;
		struct timespec ts;

		next += period;
		ts = to_ts(next);
		while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL) == EINTR)
			;
		if (LOAD(&stopping))
			break;
		now = now_ns();
		beat_round(now, &seen);
		if (next + period < now) /* late by more than a period: no burst of rounds */
			next = now;
	}
	return NULL;
}

/* Creates the thread with every signal blocked (the JVM's signals are for its own threads). */
static int spawn(pthread_attr_t *attr)
{
	sigset_t all, old;
	int r;

	sigfillset(&all);
	pthread_sigmask(SIG_SETMASK, &all, &old);
	r = pthread_create(&thread, attr, beat_main, NULL);
	pthread_sigmask(SIG_SETMASK, &old, NULL);
	return r;
}

int arflex_beat_start(uint64_t period_ns, uint64_t grace_ns, int fifo_priority)
{
	pthread_attr_t attr;
	int r, refused = 0;

	if (period_ns == 0 || grace_ns < period_ns || fifo_priority < 0 || fifo_priority > 99)
		return -EINVAL;
	pthread_mutex_lock(&life);
	if (running) {
		pthread_mutex_unlock(&life);
		return -EALREADY;
	}
	for (unsigned i = 0; i < ARFLEX_BEAT_SLOTS; i++)
		__atomic_store_n(&slots[i], NULL, __ATOMIC_SEQ_CST);
	memset(&st, 0, sizeof(st));
	period = period_ns;
	grace = grace_ns;
	STORE(&stopping, false);
	STORE(&alive_ns, now_ns());
	r = EPERM;
	if (fifo_priority > 0) {
		struct sched_param sp = { .sched_priority = fifo_priority };

		pthread_attr_init(&attr);
		pthread_attr_setinheritsched(&attr, PTHREAD_EXPLICIT_SCHED);
		pthread_attr_setschedpolicy(&attr, SCHED_FIFO);
		pthread_attr_setschedparam(&attr, &sp);
		r = spawn(&attr);
		pthread_attr_destroy(&attr);
		if (r == 0)
			st.fifo = fifo_priority;
		else
			refused = r;
	}
	if (r != 0) {
		r = spawn(NULL);
		if (r != 0) {
			pthread_mutex_unlock(&life);
			return -r;
		}
	}
	running = true;
	pthread_mutex_unlock(&life);
	return refused;
}

void arflex_beat_stop(void)
{
	pthread_mutex_lock(&life);
	if (running) {
		STORE(&stopping, true);
		pthread_join(thread, NULL);
		running = false;
		for (unsigned i = 0; i < ARFLEX_BEAT_SLOTS; i++)
			__atomic_store_n(&slots[i], NULL, __ATOMIC_SEQ_CST);
	}
	pthread_mutex_unlock(&life);
}

void arflex_beat_java_alive(void)
{
	STORE(&alive_ns, now_ns());
}

int arflex_beat_add(void *ctl)
{
	if (!ctl)
		return -EINVAL;
	for (unsigned i = 0; i < ARFLEX_BEAT_SLOTS; i++)
		if (__atomic_load_n(&slots[i], __ATOMIC_SEQ_CST) == ctl)
			return -EEXIST;
	for (unsigned i = 0; i < ARFLEX_BEAT_SLOTS; i++) {
		void *expected = NULL;

		if (__atomic_compare_exchange_n(&slots[i], &expected, ctl, false, __ATOMIC_SEQ_CST,
						__ATOMIC_SEQ_CST)) {
			__atomic_add_fetch(&st.registered, 1, __ATOMIC_RELAXED);
			return 0;
		}
	}
	return -ENOSPC;
}

int arflex_beat_remove(void *ctl)
{
	bool found = false;
	uint64_t seq, deadline;

	if (!ctl)
		return -ENOENT;
	for (unsigned i = 0; i < ARFLEX_BEAT_SLOTS && !found; i++) {
		void *expected = ctl;

		found = __atomic_compare_exchange_n(&slots[i], &expected, NULL, false,
						    __ATOMIC_SEQ_CST, __ATOMIC_SEQ_CST);
	}
	if (!found)
		return -ENOENT;
	__atomic_sub_fetch(&st.registered, 1, __ATOMIC_RELAXED);
	/* A round that began before the slot was cleared may still write into @ctl: wait it out. */
	seq = __atomic_load_n(&round_seq, __ATOMIC_SEQ_CST);
	if (!(seq & 1))
		return 0;
	deadline = now_ns() + REMOVE_WAIT_NS;
	while (__atomic_load_n(&round_seq, __ATOMIC_SEQ_CST) == seq) {
		struct timespec ts = { 0, 50000 };

		if (now_ns() > deadline)
			return -ETIMEDOUT;
		nanosleep(&ts, NULL);
	}
	return 0;
}

void arflex_beat_stats(struct arflex_beat_stats *out)
{
	out->rounds = __atomic_load_n(&st.rounds, __ATOMIC_RELAXED);
	out->withheld = __atomic_load_n(&st.withheld, __ATOMIC_RELAXED);
	out->bridged = __atomic_load_n(&st.bridged, __ATOMIC_RELAXED);
	out->max_silence_ns = LOAD(&st.max_silence_ns);
	out->last_silence_ns = LOAD(&st.last_silence_ns);
	out->registered = __atomic_load_n(&st.registered, __ATOMIC_RELAXED);
	out->fifo = __atomic_load_n(&st.fifo, __ATOMIC_RELAXED);
	out->max_gap_ns = LOAD(&st.max_gap_ns);
	out->last_round_ns = LOAD(&st.last_round_ns);
}
