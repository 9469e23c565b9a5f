/* Sporadic tasks (SPEC §4.2, DECISIONS.md D27): the probe, run as a sporadic task, is released
 * by new samples on its first declared input ('in'), at most once per period. */
#include <errno.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "arflex/host.h"
#include "helper.h"
#include "probe_kit.h"

#define PERIOD 1000000ull /* probe_host's period: the minimum inter-arrival */

static struct arflex_port feed;
static char feed_name[ARFLEX_OBJ_NAME_SIZE];

static void sporadic_probe(struct arflex_host *h, const char *tag, uint64_t hb_timeout)
{
	struct arflex_port_spec spec = { .method = ARFLEX_PORT_STATE, .type = value_type };

	setup_ids(tag);
	snprintf(feed_name, sizeof(feed_name), "/arflex.%s.feed.out.v", rid);
	assert_int_equal(arflex_port_create(&feed, feed_name, &spec), 0);
	probe_task_type = ARFLEX_TASK_SPORADIC;
	assert_int_equal(probe_host(h, "probe", hb_timeout, 0, true), 0);
	probe_task_type = ARFLEX_TASK_PERIODIC;
	spawn_ready(h);
}

static void finish(struct arflex_host *h)
{
	shutdown_ok(h);
	arflex_host_destroy(h);
	assert_int_equal(arflex_port_destroy(&feed), 0);
	unlink(logpath);
	th_assert_clean(rid);
}

static struct arflex_stats st;

static const struct arflex_stats *stats(struct arflex_host *h)
{
	assert_int_equal(arflex_ctl_stats_read(h->ctl, &st), 0);
	return &st;
}

/* Waits (deadline 10 s) until the RT thread's own heartbeat has advanced @periods periods past
 * its value now: the RT thread was alive and polling all that time, by its own clock. */
static void rt_progress(struct arflex_host *h, uint64_t periods)
{
	uint64_t from = __atomic_load_n(&h->ctl->rt_hb_ns, __ATOMIC_ACQUIRE);
	uint64_t deadline = arflex_sys_now_ns() + 10 * SEC;

	assert_true(from != 0);
	while (__atomic_load_n(&h->ctl->rt_hb_ns, __ATOMIC_ACQUIRE) < from + periods * PERIOD) {
		assert_true(arflex_sys_now_ns() < deadline);
		arflex_sys_sleep_until(arflex_sys_now_ns() + 1000000);
	}
}

static uint64_t out_head(struct arflex_host *h)
{
	return __atomic_load_n(&arflex_host_output(h, "out")->hdr->head, __ATOMIC_ACQUIRE);
}

static bool updates_are(const struct probe_out *o, uint64_t n) { return o->updates == n; }

static void one_update_per_sample(void **state)
{
	enum { N = 20 };
	struct arflex_host h;
	struct probe_out o;
	uint64_t v;

	(void)state;
	sporadic_probe(&h, "spo1", 0);
	assert_int_equal(arflex_host_start(&h, T_CALL), 0);
	/* bound while running: the polls are cycle boundaries; no sample yet, no update */
	assert_int_equal(arflex_host_bind(&h, "in", feed_name, T_CALL), 0);
	rt_progress(&h, 20);
	assert_int_equal(out_head(&h), 0);
	assert_int_equal(stats(&h)->cycles, 0);

	/* N samples, each after the previous one was handled: N updates, each saw its sample */
	for (v = 1; v <= N; v++) {
		assert_int_equal(arflex_state_write(&feed, &v, sizeof(v)), 0);
		assert_true(wait_out(&h, updates_are, v, false));
		assert_true(read_out(&h, &o));
		assert_int_equal(o.in_value, v);
		assert_int_equal(o.in_reads, v);
	}
	/* no sample: no update, while the RT thread keeps polling for 20 periods */
	rt_progress(&h, 20);
	assert_true(read_out(&h, &o));
	assert_int_equal(o.updates, N);
	assert_int_equal(out_head(&h), N);
	stats(&h);
	assert_int_equal(st.cycles, N);
	assert_int_equal(st.latency.count, N); /* latency from each release */
	assert_int_equal(st.exec.count, N);
	assert_true(st.latency.max_ns >= st.latency.min_ns);
	assert_int_equal(st.overruns, 0);      /* one sample at a time: nothing coalesced */
	assert_int_equal(st.missed_periods, 0);
	assert_true(st.last_release_ns != 0);
	finish(&h);
}

static void burst_is_coalesced_and_counted(void **state)
{
	enum { K = 500 };
	struct arflex_host h;
	struct probe_out o;
	uint64_t v = 1, deadline, runs;

	(void)state;
	sporadic_probe(&h, "spo2", 0);
	assert_int_equal(arflex_host_bind(&h, "in", feed_name, T_CALL), 0);
	assert_int_equal(arflex_host_start(&h, T_CALL), 0);
	assert_int_equal(arflex_state_write(&feed, &v, sizeof(v)), 0);
	assert_true(wait_out(&h, updates_are, 1, false));

	/* K samples back to back, far faster than the minimum inter-arrival (1 ms) */
	for (v = 2; v <= K + 1; v++)
		assert_int_equal(arflex_state_write(&feed, &v, sizeof(v)), 0);
	/* every sample is either run or counted as coalesced */
	deadline = arflex_sys_now_ns() + 10 * SEC;
	while (stats(&h)->cycles + st.missed_periods < K + 1) {
		assert_true(arflex_sys_now_ns() < deadline);
		arflex_sys_sleep_until(arflex_sys_now_ns() + 1000000);
	}
	rt_progress(&h, 20);
	stats(&h);
	runs = st.cycles - 1;
	assert_int_equal(st.cycles + st.missed_periods, K + 1);
	assert_true(runs >= 1 && runs < K / 2); /* not run faster than the period */
	assert_true(st.overruns >= 1 && st.overruns <= runs);
	assert_true(h.ctl->warnings[ARFLEX_WARN_OVERRUN] >= 1);
	assert_true(read_out(&h, &o));
	assert_int_equal(o.updates, st.cycles);
	assert_int_equal(o.in_value, K + 1); /* the newest sample is always run */
	finish(&h);
}

/* Safe mode does not wait for input: with no sample at all the safe hook runs every period. */
static void safe_mode_runs_without_samples(void **state)
{
	struct arflex_host h;
	struct probe_out o;

	(void)state;
	sporadic_probe(&h, "spo3", 100000000);
	arflex_host_heartbeat(&h);
	assert_int_equal(arflex_host_start(&h, T_CALL), 0);
	assert_true(wait_out(&h, safe_above, 3, false)); /* no heartbeat, no input */
	assert_true(arflex_ctl_flags(h.ctl) & ARFLEX_FLAG_SAFE_ACTIVE);
	assert_true(read_out(&h, &o));
	assert_int_equal(o.updates, 0);
	assert_int_equal(o.safe_firsts, 1);
	/* heartbeat back: updates again only on samples */
	assert_int_equal(arflex_host_bind(&h, "in", feed_name, T_CALL), 0);
	for (uint64_t v = 1; v <= 3; v++) {
		arflex_host_heartbeat(&h);
		assert_int_equal(arflex_state_write(&feed, &v, sizeof(v)), 0);
		assert_true(wait_out(&h, updates_are, v, true));
	}
	arflex_host_heartbeat(&h);
	finish(&h);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(one_update_per_sample),
		cmocka_unit_test(burst_is_coalesced_and_counted),
		cmocka_unit_test(safe_mode_runs_without_samples),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
