/* The runtime heartbeat's native writer (arflex/beat.h): writes while the manager is alive,
 * withholds after the grace, bridges shorter silences, and never touches a removed block. */
#define _GNU_SOURCE
#include <errno.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <time.h>

#include <cmocka.h>

#include "arflex/beat.h"
#include "arflex/control.h"
#include "helper.h"

#define MS 1000000ull

static struct arflex_ctl a, b;

static uint64_t mono(void)
{
	struct timespec ts;

	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (uint64_t)ts.tv_sec * 1000000000ull + (uint64_t)ts.tv_nsec;
}

static uint64_t hb(const struct arflex_ctl *c)
{
	return __atomic_load_n(&c->runtime_hb_ns, __ATOMIC_ACQUIRE);
}

static struct arflex_beat_stats stats(void)
{
	struct arflex_beat_stats s;

	arflex_beat_stats(&s);
	return s;
}

/* One poll step (0.2 ms), saying the manager is alive when @alive. */
static void step(bool alive)
{
	struct timespec ts = { 0, 200000 };

	if (alive)
		arflex_beat_java_alive();
	nanosleep(&ts, NULL);
}

/* Waits for @cond (polled, at most 5 s), the manager alive each poll when @alive. */
#define AWAIT(cond, alive)                                                                     \
	do {                                                                                   \
		uint64_t end_ = mono() + 5000 * MS;                                            \
		while (!(cond)) {                                                              \
			assert_true(mono() < end_);                                            \
			step(alive);                                                           \
		}                                                                              \
	} while (0)

static int teardown(void **state)
{
	(void)state;
	arflex_beat_stop();
	assert_int_equal(th_threads(), 1); /* the writer thread was joined */
	return 0;
}

static void refuses_bad_arguments(void **state)
{
	(void)state;
	assert_int_equal(arflex_beat_start(0, 10 * MS, 0), -EINVAL);
	assert_int_equal(arflex_beat_start(10 * MS, 5 * MS, 0), -EINVAL);
	assert_int_equal(arflex_beat_start(MS, 10 * MS, 100), -EINVAL);
	assert_int_equal(arflex_beat_start(MS, 10 * MS, 0), 0);
	assert_int_equal(arflex_beat_start(MS, 10 * MS, 0), -EALREADY);
	assert_int_equal(arflex_beat_add(NULL), -EINVAL);
}

static void writes_every_block_while_alive(void **state)
{
	uint64_t t0 = mono(), v;

	(void)state;
	a.runtime_hb_ns = 0;
	b.runtime_hb_ns = 0;
	/* a grace far longer than any descheduling of this test thread: nothing is withheld */
	assert_int_equal(arflex_beat_start(MS, 2000 * MS, 0), 0);
	assert_int_equal(arflex_beat_add(&a), 0);
	assert_int_equal(arflex_beat_add(&b), 0);
	assert_int_equal(arflex_beat_add(&a), -EEXIST);
	assert_int_equal(stats().registered, 2);
	AWAIT(hb(&a) >= t0 && hb(&b) >= t0, true);
	v = hb(&a);
	AWAIT(hb(&a) > v, true);
	assert_true(hb(&a) <= mono());
	assert_int_equal(stats().withheld, 0);
}

static void withholds_after_the_grace_and_resumes(void **state)
{
	uint64_t v, w;

	(void)state;
	assert_int_equal(arflex_beat_start(MS, 20 * MS, 0), 0);
	assert_int_equal(arflex_beat_add(&a), 0);
	AWAIT(stats().rounds > 3, true);
	/* the manager goes silent: after 20 ms the writer withholds */
	AWAIT(stats().withheld > 0, false);
	v = hb(&a);
	w = stats().withheld;
	AWAIT(stats().withheld >= w + 10, false);
	assert_int_equal(hb(&a), v);
	assert_true(stats().max_silence_ns > 20 * MS);
	/* alive again: the heartbeat resumes */
	arflex_beat_java_alive();
	AWAIT(hb(&a) > v, true);
	/* (not asserted: bridged, since a descheduled test thread makes short silences of its own) */
}

static void bridges_a_silence_within_the_grace(void **state)
{
	uint64_t v;

	(void)state;
	assert_int_equal(arflex_beat_start(MS, 500 * MS, 0), 0);
	assert_int_equal(arflex_beat_add(&a), 0);
	AWAIT(stats().rounds > 3, true);
	v = hb(&a);
	/* silent for 10 ms (five periods): the writer goes on */
	AWAIT(stats().last_silence_ns >= 10 * MS, false);
	assert_true(hb(&a) > v);
	arflex_beat_java_alive();
	AWAIT(stats().bridged >= 1, true);
	assert_int_equal(stats().withheld, 0);
	assert_true(stats().max_silence_ns >= 10 * MS);
}

/* D75: the writer's own lateness is kept, so a lost heartbeat can be told from a late writer */
static void keeps_its_own_longest_gap_and_last_round(void **state)
{
	uint64_t t0 = mono(), r;

	(void)state;
	assert_int_equal(arflex_beat_start(2 * MS, 2000 * MS, 0), 0);
	AWAIT(stats().rounds >= 3, true);
	/* two rounds or more: a gap between them of at least about one period */
	assert_true(stats().max_gap_ns >= MS);
	assert_true(stats().last_round_ns >= t0 && stats().last_round_ns <= mono());
	r = stats().rounds;
	AWAIT(stats().rounds > r, true);
	assert_true(stats().last_round_ns >= t0 + 2 * MS);
}

static void a_removed_block_is_never_written(void **state)
{
	uint64_t r;

	(void)state;
	assert_int_equal(arflex_beat_start(MS, 50 * MS, 0), 0);
	assert_int_equal(arflex_beat_add(&a), 0);
	AWAIT(hb(&a) != 0, true);
	assert_int_equal(arflex_beat_remove(&a), 0);
	assert_int_equal(arflex_beat_remove(&a), -ENOENT);
	assert_int_equal(stats().registered, 0);
	__atomic_store_n(&a.runtime_hb_ns, 7, __ATOMIC_RELEASE);
	r = stats().rounds;
	AWAIT(stats().rounds >= r + 10, true);
	assert_int_equal(hb(&a), 7);
}

static void slots_are_bounded(void **state)
{
	(void)state;
	/* no writer running: the pointers are registered, never dereferenced */
	for (uintptr_t i = 0; i < ARFLEX_BEAT_SLOTS; i++)
		assert_int_equal(arflex_beat_add((void *)(0x10000 + 64 * i)), 0);
	assert_int_equal(arflex_beat_add(&a), -ENOSPC);
	for (uintptr_t i = 0; i < ARFLEX_BEAT_SLOTS; i++)
		assert_int_equal(arflex_beat_remove((void *)(0x10000 + 64 * i)), 0);
	assert_int_equal(arflex_beat_add(&a), 0);
	assert_int_equal(arflex_beat_remove(&a), 0);
}

static void fifo_as_asked_or_says_why_not(void **state)
{
	int r;

	(void)state;
	r = arflex_beat_start(MS, 50 * MS, 1);
	assert_true(r >= 0);
	assert_int_equal(stats().fifo, r == 0 ? 1 : 0);
	AWAIT(stats().rounds > 2, true);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test_teardown(refuses_bad_arguments, teardown),
		cmocka_unit_test_teardown(writes_every_block_while_alive, teardown),
		cmocka_unit_test_teardown(withholds_after_the_grace_and_resumes, teardown),
		cmocka_unit_test_teardown(bridges_a_silence_within_the_grace, teardown),
		cmocka_unit_test_teardown(keeps_its_own_longest_gap_and_last_round, teardown),
		cmocka_unit_test_teardown(a_removed_block_is_never_written, teardown),
		cmocka_unit_test_teardown(slots_are_bounded, teardown),
		cmocka_unit_test_teardown(fifo_as_asked_or_says_why_not, teardown),
	};

	return cmocka_run_group_tests_name("rt-core.beat", tests, NULL, NULL);
}
