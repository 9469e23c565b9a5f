/* rt-core.component.exit: A probe component's end and its restart: SIGTERM stops it cleanly, SIGKILL mid-cycle leaves
 * nothing behind, a restart reuses the objects and waits for the reset.
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

static void sigterm_stops_cleanly(void **state)
{
	struct arflex_host h;
	char log[256];

	(void)state;
	setup_ids("term");
	assert_int_equal(probe_host(&h, "probe", 0, 0, true), 0);
	spawn_ready(&h);
	assert_int_equal(arflex_host_start(&h, T_CALL), 0);
	assert_true(wait_out(&h, updates_above, 5, false));
	assert_int_equal(arflex_host_kill(&h, SIGTERM), 0);
	assert_int_equal(arflex_host_wait_exit(&h, 10 * SEC), 0);
	assert_int_equal(WEXITSTATUS(arflex_host_exit_status(&h)), 0);
	assert_int_equal(arflex_ctl_state(h.ctl), ARFLEX_STATE_EXITED);
	arflex_host_destroy(&h);
	assert_true(th_read_file(logpath, log, sizeof(log)) > 0);
	assert_string_equal(log, "configure\nstart\nupdate\nstop\ncleanup\n");
	unlink(logpath);
	th_assert_clean(rid);
}

static void killed_mid_cycle_leaves_nothing(void **state)
{
	struct arflex_host h;

	(void)state;
	setup_ids("kill");
	assert_int_equal(probe_host(&h, "probe", 0, 0, true), 0);
	spawn_ready(&h);
	assert_int_equal(arflex_host_start(&h, T_CALL), 0);
	assert_true(wait_out(&h, updates_above, 5, false));
	assert_int_equal(arflex_host_kill(&h, SIGKILL), 0);
	assert_int_equal(arflex_host_wait_exit(&h, 10 * SEC), 0);
	assert_true(WIFSIGNALED(arflex_host_exit_status(&h)));
	arflex_host_destroy(&h);
	unlink(logpath);
	th_assert_clean(rid);
}

static void restart_reuses_objects_and_waits_for_reset(void **state)
{
	struct arflex_host h;
	struct probe_out o;
	uint64_t v, head;

	(void)state;
	setup_ids("restart");
	assert_int_equal(probe_host(&h, "arm", 0, ARFLEX_CFG_MOVES_HARDWARE, true), 0);
	spawn_ready(&h);
	assert_int_equal(arflex_host_start(&h, T_CALL), 0);
	assert_int_equal(arflex_host_set_param(&h, "gain", 9, NULL, T_CALL), 0);
	assert_true(wait_out(&h, gain_is, 9, false));
	assert_int_equal(arflex_host_kill(&h, SIGKILL), 0);
	assert_int_equal(arflex_host_wait_exit(&h, 10 * SEC), 0);
	head = arflex_host_output(&h, "out")->hdr->head;

	/* the supervisor restarts it on the same objects; motion needs the operator */
	__atomic_or_fetch(&h.ctl->flags, ARFLEX_FLAG_RESET_REQUIRED, __ATOMIC_RELEASE);
	spawn_ready(&h);
	assert_int_equal(arflex_ctl_flags(h.ctl), ARFLEX_FLAG_RESET_REQUIRED);
	assert_int_equal(arflex_host_get_param(&h, "gain", &v, T_CALL), 0);
	assert_int_equal(v, 9); /* the request survives the restart */
	assert_int_equal(arflex_host_start(&h, T_CALL), 0);
	assert_true(wait_out(&h, safe_above, 3, true));
	assert_true(arflex_ctl_flags(h.ctl) & ARFLEX_FLAG_SAFE_ACTIVE);
	assert_int_equal(arflex_host_reset(&h, T_CALL), 0);
	assert_true(read_out(&h, &o));
	assert_true(wait_out(&h, updates_above, o.updates + 5, true));
	assert_true(arflex_host_output(&h, "out")->hdr->head > head); /* one sequence */
	shutdown_ok(&h);
	arflex_host_destroy(&h);
	unlink(logpath);
	th_assert_clean(rid);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(sigterm_stops_cleanly),
		cmocka_unit_test(killed_mid_cycle_leaves_nothing),
		cmocka_unit_test(restart_reuses_objects_and_waits_for_reset),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
