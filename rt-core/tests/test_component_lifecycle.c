/* rt-core.component.lifecycle: The lifecycle of a probe component in a real child process: its hooks in order over two
 * START/STOP runs and the commands' errors, a configure or start that fails, scheduling in force
 * or warned, a bad command line.
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

static void lifecycle_hooks_in_order(void **state)
{
	struct arflex_host h;
	struct arflex_msg rsp;
	struct probe_out o;
	uint64_t v;
	char log[512];

	(void)state;
	setup_ids("life");
	assert_int_equal(probe_host(&h, "probe", 0, 0, true), 0);
	spawn_ready(&h);
	assert_int_equal(h.ctl->pid, h.pid);
	assert_int_equal(arflex_host_call(&h, ARFLEX_CMD_PING, NULL, NULL, T_CALL), 0);
	assert_int_equal(arflex_host_stop(&h, T_CALL), -EALREADY);
	assert_int_equal(arflex_host_start(&h, T_CALL), 0);
	assert_int_equal(arflex_host_start(&h, T_CALL), -EALREADY);
	assert_true(wait_out(&h, updates_above, 20, false));

	assert_int_equal(arflex_host_set_param(&h, "gain", 5, &v, T_CALL), 0);
	assert_int_equal(v, 5);
	assert_true(wait_out(&h, gain_is, 5, false));
	assert_int_equal(arflex_host_set_param(&h, "gain", 5000, NULL, T_CALL), -ERANGE);
	assert_int_equal(arflex_host_set_param(&h, "scale", arflex_f64_bits(2.0), NULL, T_CALL),
			 -EPERM);
	assert_int_equal(arflex_host_set_param(&h, "nope", 1, NULL, T_CALL), -ENOENT);
	assert_int_equal(arflex_host_get_param(&h, "gain", &v, T_CALL), 0);
	assert_int_equal(v, 5);

	assert_int_equal(arflex_host_call(&h, ARFLEX_CMD_GET_STATE, NULL, &rsp, T_CALL), 0);
	assert_int_equal(rsp.u.state.state, ARFLEX_STATE_RUNNING);
	assert_int_equal(rsp.u.state.pid, h.pid);
	assert_true(rsp.u.state.cycles > 0);
	assert_int_equal(arflex_host_call(&h, ARFLEX_CMD_GET_STATS, NULL, &rsp, T_CALL), 0);
	assert_true(rsp.u.stats.cycles > 20);
	assert_true(rsp.u.stats.latency.max_ns >= rsp.u.stats.latency.min_ns);
	assert_true(rsp.u.stats.exec.p999_ns >= rsp.u.stats.exec.p50_ns);
	assert_int_equal(arflex_host_call(&h, 77, NULL, NULL, T_CALL), -ENOSYS);

	assert_int_equal(arflex_host_stop(&h, T_CALL), 0);
	assert_int_equal(arflex_ctl_state(h.ctl), ARFLEX_STATE_READY);
	/* immutable parameters may change while not running */
	assert_int_equal(arflex_host_set_param(&h, "scale", arflex_f64_bits(2.0), &v, T_CALL), 0);
	assert_true(arflex_bits_f64(v) == 2.0);
	assert_true(read_out(&h, &o));
	assert_int_equal(arflex_host_start(&h, T_CALL), 0);
	assert_true(wait_out(&h, updates_above, o.updates + 5, false));
	assert_int_equal(arflex_host_stop(&h, T_CALL), 0);
	shutdown_ok(&h);
	arflex_host_destroy(&h);

	assert_true(th_read_file(logpath, log, sizeof(log)) > 0);
	assert_string_equal(log, "configure\nstart\nupdate\nstop\nstart\nupdate\nstop\ncleanup\n");
	unlink(logpath);
	th_assert_clean(rid);
}

static void failing_configure_leaves_nothing(void **state)
{
	struct arflex_host h;
	char log[256];

	(void)state;
	setup_ids("cfgfail");
	make_env("ARFLEX_PROBE_FAIL_CONFIGURE=1");
	assert_int_equal(probe_host(&h, "probe", 0, 0, true), 0);
	assert_int_equal(arflex_host_spawn(&h, ARFLEX_PROBE_EXE, NULL, envp), 0);
	assert_int_equal(arflex_host_wait_exit(&h, 10 * SEC), 0);
	assert_int_equal(WEXITSTATUS(arflex_host_exit_status(&h)), ARFLEX_EXIT_CONFIGURE);
	assert_int_equal(arflex_ctl_state(h.ctl), ARFLEX_STATE_FAILED);
	assert_int_equal(h.ctl->exit_status, -ENOTSUP);
	arflex_host_destroy(&h);
	assert_true(th_read_file(logpath, log, sizeof(log)) > 0);
	assert_string_equal(log, "configure\nconfigure-failed\n");
	unlink(logpath);
	th_assert_clean(rid);

	/* the manager did not create the output port: configure fails cleanly too */
	make_env(NULL);
	assert_int_equal(probe_host(&h, "probe", 0, 0, false), 0);
	assert_int_equal(arflex_host_spawn(&h, ARFLEX_PROBE_EXE, NULL, envp), 0);
	assert_int_equal(arflex_host_wait_exit(&h, 10 * SEC), 0);
	assert_int_equal(WEXITSTATUS(arflex_host_exit_status(&h)), ARFLEX_EXIT_CONFIGURE);
	assert_int_equal(h.ctl->exit_status, -ENOENT);
	arflex_host_destroy(&h);
	unlink(logpath);
	th_assert_clean(rid);
}

static void failing_start_is_refused(void **state)
{
	struct arflex_host h;
	char log[256];

	(void)state;
	setup_ids("startfail");
	make_env("ARFLEX_PROBE_FAIL_START=1");
	assert_int_equal(probe_host(&h, "probe", 0, 0, true), 0);
	spawn_ready(&h);
	assert_int_equal(arflex_host_start(&h, T_CALL), -ENOTSUP);
	assert_int_equal(arflex_ctl_state(h.ctl), ARFLEX_STATE_READY);
	assert_int_equal(arflex_host_start(&h, T_CALL), -ENOTSUP);
	shutdown_ok(&h);
	arflex_host_destroy(&h);
	assert_true(th_read_file(logpath, log, sizeof(log)) > 0);
	assert_string_equal(log, "configure\nstart\nstart\ncleanup\n");
	unlink(logpath);
	th_assert_clean(rid);
}

/* SCHED_FIFO and affinity are either in force (flags) or refused with a counted warning. */
static void scheduling_applied_or_warned(void **state)
{
	struct arflex_host h;
	uint32_t f;

	(void)state;
	setup_ids("sched");
	probe_prio = 10;
	probe_cpus = 1;
	assert_int_equal(probe_host(&h, "probe", 0, 0, true), 0);
	probe_prio = 0;
	probe_cpus = 0;
	spawn_ready(&h);
	assert_int_equal(arflex_host_start(&h, T_CALL), 0);
	assert_true(wait_out(&h, updates_above, 5, false));
	f = arflex_ctl_flags(h.ctl);
	assert_true((f & ARFLEX_FLAG_SCHED_FIFO) || h.ctl->warnings[ARFLEX_WARN_SCHED] == 1);
	assert_true((f & ARFLEX_FLAG_AFFINITY) || h.ctl->warnings[ARFLEX_WARN_AFFINITY] == 1);
	assert_false(f & ARFLEX_FLAG_MLOCKALL); /* disabled by cfg_flags */
	assert_int_equal(h.ctl->warnings[ARFLEX_WARN_MLOCK], 0);
	shutdown_ok(&h);
	arflex_host_destroy(&h);
	unlink(logpath);
	th_assert_clean(rid);
}

static void bad_command_line(void **state)
{
	struct arflex_host h;
	char *extra[] = { (char *)"--bogus", NULL };

	(void)state;
	setup_ids("args");
	assert_int_equal(probe_host(&h, "probe", 0, 0, true), 0);
	assert_int_equal(arflex_host_spawn(&h, ARFLEX_PROBE_EXE, extra, envp), 0);
	assert_int_equal(arflex_host_wait_exit(&h, 10 * SEC), 0);
	assert_int_equal(WEXITSTATUS(arflex_host_exit_status(&h)), ARFLEX_EXIT_USAGE);
	assert_int_equal(arflex_ctl_state(h.ctl), ARFLEX_STATE_CREATED);
	arflex_host_destroy(&h);
	unlink(logpath);
	th_assert_clean(rid);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(lifecycle_hooks_in_order),
		cmocka_unit_test(failing_configure_leaves_nothing),
		cmocka_unit_test(failing_start_is_refused),
		cmocka_unit_test(scheduling_applied_or_warned),
		cmocka_unit_test(bad_command_line),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
