/* rt-core.component.safety: Safe mode and the operator's reset with a probe component: safe when the runtime's heartbeat
 * stops, a component that moves hardware waits for a reset, a reset the component latches itself.
 * (The other jobs of the component API: test_component_*.c; the probe: probe.c, probe_kit.h.) */
#include <errno.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#include "arflex/host.h"
#include "helper.h"
#include "probe_kit.h"

static void safe_when_heartbeat_stops(void **state)
{
	struct arflex_host h;
	struct probe_out o;

	(void)state;
	setup_ids("safe");
	assert_int_equal(probe_host(&h, "probe", 100000000, 0, true), 0);
	spawn_ready(&h);
	arflex_host_heartbeat(&h);
	assert_int_equal(arflex_host_start(&h, T_CALL), 0);
	/* no heartbeat from now on */
	assert_true(wait_out(&h, safe_above, 3, false));
	assert_true(arflex_ctl_flags(h.ctl) & ARFLEX_FLAG_SAFE_ACTIVE);
	assert_false(arflex_ctl_flags(h.ctl) & ARFLEX_FLAG_RESET_REQUIRED);
	assert_true(h.ctl->warnings[ARFLEX_WARN_SAFE] >= 1);
	/* D75: the cause is said: the heartbeat, not a reset */
	assert_true(h.ctl->warnings[ARFLEX_WARN_HB_LOST] >= 1);
	assert_int_equal(h.ctl->warnings[ARFLEX_WARN_RESET], 0);
	assert_true(read_out(&h, &o));
	assert_int_equal(o.safe_firsts, 1);
	/* heartbeat back: without "moves hardware" the component resumes by itself */
	assert_true(wait_out(&h, updates_above, o.updates + 10, true));
	assert_false(arflex_ctl_flags(h.ctl) & ARFLEX_FLAG_SAFE_ACTIVE);
	arflex_host_heartbeat(&h);
	shutdown_ok(&h);
	arflex_host_destroy(&h);
	unlink(logpath);
	th_assert_clean(rid);
}

static void moves_hardware_needs_operator_reset(void **state)
{
	struct arflex_host h;
	struct probe_out o;
	uint64_t until;

	(void)state;
	setup_ids("reset");
	assert_int_equal(probe_host(&h, "arm", 100000000, ARFLEX_CFG_MOVES_HARDWARE, true), 0);
	spawn_ready(&h);
	arflex_host_heartbeat(&h);
	assert_int_equal(arflex_host_start(&h, T_CALL), 0);
	assert_true(wait_out(&h, safe_above, 3, false));
	assert_true(arflex_ctl_flags(h.ctl) & ARFLEX_FLAG_RESET_REQUIRED);
	/* D75: the reset was latched for the heartbeat: that is the cause said */
	assert_true(h.ctl->warnings[ARFLEX_WARN_HB_LOST] >= 1);
	assert_int_equal(h.ctl->warnings[ARFLEX_WARN_RESET], 0);
	assert_int_equal(arflex_host_reset(&h, T_CALL), -EAGAIN); /* heartbeat still stale */
	/* fresh heartbeat alone does not resume motion */
	assert_true(read_out(&h, &o));
	assert_true(wait_out(&h, safe_above, o.safe_calls + 20, true));
	assert_true(read_out(&h, &o));
	until = o.updates;
	assert_true(arflex_ctl_flags(h.ctl) & ARFLEX_FLAG_SAFE_ACTIVE);
	arflex_host_heartbeat(&h);
	assert_int_equal(arflex_host_reset(&h, T_CALL), 0);
	assert_true(wait_out(&h, updates_above, until + 10, true));
	assert_false(arflex_ctl_flags(h.ctl) & (ARFLEX_FLAG_SAFE_ACTIVE |
						ARFLEX_FLAG_RESET_REQUIRED));
	arflex_host_heartbeat(&h);
	shutdown_ok(&h);
	arflex_host_destroy(&h);
	unlink(logpath);
	th_assert_clean(rid);
}

/* arflex_component_require_reset: the component latches a reset itself; no update runs
 * until the operator's RESET. */
static void component_requires_reset(void **state)
{
	struct arflex_host h;
	struct probe_out o;
	uint64_t safe_before;

	(void)state;
	setup_ids("reqreset");
	make_env("ARFLEX_PROBE_REQUIRE_RESET_AT=5");
	assert_int_equal(probe_host(&h, "probe", 0, 0, true), 0);
	spawn_ready(&h);
	assert_false(arflex_ctl_flags(h.ctl) & ARFLEX_FLAG_RESET_REQUIRED);
	assert_int_equal(arflex_host_start(&h, T_CALL), 0);
	assert_true(wait_out(&h, safe_above, 10, false));
	assert_true(arflex_ctl_flags(h.ctl) & ARFLEX_FLAG_RESET_REQUIRED);
	assert_true(arflex_ctl_flags(h.ctl) & ARFLEX_FLAG_SAFE_ACTIVE);
	assert_true(read_out(&h, &o));
	assert_int_equal(o.updates, 5); /* none after the one that latched */
	assert_int_equal(o.safe_firsts, 1);
	/* D75: safe mode for the component's own latch, not for the heartbeat (none is judged) */
	assert_int_equal(h.ctl->warnings[ARFLEX_WARN_RESET], 1);
	assert_int_equal(h.ctl->warnings[ARFLEX_WARN_HB_LOST], 0);
	safe_before = o.safe_calls;
	assert_int_equal(arflex_host_reset(&h, T_CALL), 0);
	assert_true(wait_out(&h, updates_above, 15, false));
	assert_false(arflex_ctl_flags(h.ctl) & (ARFLEX_FLAG_SAFE_ACTIVE |
						ARFLEX_FLAG_RESET_REQUIRED));
	assert_true(read_out(&h, &o));
	assert_true(o.safe_calls >= safe_before);
	shutdown_ok(&h);
	arflex_host_destroy(&h);
	unlink(logpath);
	th_assert_clean(rid);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(safe_when_heartbeat_stops),
		cmocka_unit_test(moves_hardware_needs_operator_reset),
		cmocka_unit_test(component_requires_reset),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
