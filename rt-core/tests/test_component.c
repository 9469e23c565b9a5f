/* The template's lifecycle with a probe component in a real child process. */
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

static void params_applied_at_cycle_boundary(void **state)
{
	struct arflex_host h;
	struct probe_out o;
	uint64_t v, seq, deadline;
	int idx;

	(void)state;
	setup_ids("param");
	assert_int_equal(probe_host(&h, "probe", 0, 0, true), 0);
	spawn_ready(&h);
	assert_int_equal(arflex_host_start(&h, T_CALL), 0);
	for (int i = 0; i < 300; i++) {
		assert_int_equal(arflex_host_set_param(&h, "gain", (uint64_t)(i % 2 ? -i : i), &v,
						       T_CALL), 0);
		assert_int_equal((int64_t)v, i % 2 ? -i : i);
	}
	/* the direct path: the manager writes the request into the control block */
	idx = arflex_ctl_param_find(h.ctl, "gain");
	assert_true(idx >= 0);
	seq = arflex_ctl_param_request(h.ctl, (unsigned)idx, 777);
	deadline = arflex_sys_now_ns() + 10 * SEC;
	while (__atomic_load_n(&h.ctl->params[idx].applied_seq, __ATOMIC_ACQUIRE) != seq &&
	       arflex_sys_now_ns() < deadline)
		arflex_sys_sleep_until(arflex_sys_now_ns() + 1000000);
	assert_int_equal(h.ctl->params[idx].applied_seq, seq);
	assert_int_equal(h.ctl->params[idx].applied_status, 0);
	assert_true(wait_out(&h, gain_is, 777, false));
	assert_true(read_out(&h, &o));
	assert_int_equal(o.torn, 0);
	shutdown_ok(&h);
	arflex_host_destroy(&h);
	unlink(logpath);
	th_assert_clean(rid);
}

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

static void bind_and_unbind_while_running(void **state)
{
	struct arflex_port feed;
	struct arflex_port_spec spec = { .method = ARFLEX_PORT_STATE, .type = value_type };
	struct arflex_host h;
	char feed_name[ARFLEX_OBJ_NAME_SIZE], missing[ARFLEX_OBJ_NAME_SIZE];
	uint64_t v, b1, b2, b3;

	(void)state;
	setup_ids("bind");
	snprintf(feed_name, sizeof(feed_name), "/arflex.%s.feed.out.v", rid);
	snprintf(missing, sizeof(missing), "/arflex.%s.feed.out.none", rid);
	assert_int_equal(arflex_port_create(&feed, feed_name, &spec), 0);
	assert_int_equal(probe_host(&h, "probe", 0, 0, true), 0);
	spawn_ready(&h);
	/* bound before START */
	assert_int_equal(arflex_host_bind(&h, "in", feed_name, T_CALL), 0);
	v = 41;
	assert_int_equal(arflex_state_write(&feed, &v, sizeof(v)), 0);
	assert_int_equal(arflex_host_start(&h, T_CALL), 0);
	assert_true(wait_out(&h, in_is, 41, false));
	b1 = binding_of(&h);
	assert_true(b1 != 0);
	assert_int_equal(arflex_host_unbind(&h, "in", T_CALL), 0);
	assert_true(wait_out(&h, unbound, 0, false));
	assert_true(wait_out(&h, binding_is, 0, false)); /* unbound: binding 0 */
	assert_int_equal(arflex_host_unbind(&h, "in", T_CALL), -ENOTCONN);
	/* bound while running: picked up at a cycle boundary; the same provider bound again is
	 * another binding (it may have restarted) */
	assert_int_equal(arflex_host_bind(&h, "in", feed_name, T_CALL), 0);
	v = 42;
	assert_int_equal(arflex_state_write(&feed, &v, sizeof(v)), 0);
	assert_true(wait_out(&h, in_is, 42, false));
	b2 = binding_of(&h);
	assert_true(b2 != 0 && b2 != b1);
	/* rebinding replaces the old binding, without an unbind in between */
	assert_int_equal(arflex_host_bind(&h, "in", feed_name, T_CALL), 0);
	v = 43;
	assert_int_equal(arflex_state_write(&feed, &v, sizeof(v)), 0);
	assert_true(wait_out(&h, in_is, 43, false));
	b3 = binding_of(&h);
	assert_true(b3 != 0 && b3 != b2 && b3 != b1);
	/* errors */
	assert_int_equal(arflex_host_bind(&h, "in", missing, T_CALL), -ENOENT);
	assert_int_equal(arflex_host_bind(&h, "in", arflex_host_output_name(&h, "out"), T_CALL),
			 -EPROTOTYPE);
	assert_int_equal(arflex_host_bind(&h, "nope", feed_name, T_CALL), -ENOENT);
	assert_true(wait_out(&h, in_is, 43, false)); /* still bound to the feed */
	assert_int_equal(binding_of(&h), b3);          /* a refused bind is not a binding */
	shutdown_ok(&h);
	arflex_host_destroy(&h);
	assert_int_equal(arflex_port_destroy(&feed), 0);
	unlink(logpath);
	th_assert_clean(rid);
}

static bool adopted_is(const struct probe_out *o, uint64_t v)
{
	return o->adopt_calls == 1 && o->adopted == v;
}

static bool state_above(const struct probe_out *o, uint64_t v)
{
	return o->state_value > v;
}

static uint64_t state_of(struct arflex_port *p)
{
	uint64_t v = 0;

	p->last_seq = 0;
	assert_int_equal(arflex_state_read(p, &v, sizeof(v), NULL), 1);
	return v;
}

/* D41: the state block is published every cycle into the half's own state segment; a second
 * half told that segment by ADOPT takes its newest value over once, at its next START, before
 * its first update; a declared conversion is the hook's; an unknown type refuses the START. */
static void state_published_and_adopted_once(void **state)
{
	struct arflex_host a, b, c;
	struct arflex_port old;
	struct arflex_port_spec old_spec = { .method = ARFLEX_PORT_STATE,
					     .type = { "test.OldProbeState", 0, 3, sizeof(uint64_t) } };
	struct arflex_port_spec other_spec = { .method = ARFLEX_PORT_STATE,
					       .type = { "test.Other", 1, 0, sizeof(uint64_t) } };
	struct probe_out o;
	char old_name[ARFLEX_OBJ_NAME_SIZE], missing[ARFLEX_OBJ_NAME_SIZE];
	uint64_t before, v;

	(void)state;
	setup_ids("state");
	probe_state = true;
	assert_int_equal(probe_host(&a, "old", 0, 0, true), 0);
	assert_int_equal(probe_host(&b, "1-old", 0, 0, true), 0);
	probe_state = false;
	spawn_ready(&a);
	spawn_ready(&b);
	assert_int_equal(arflex_host_start(&a, T_CALL), 0);
	assert_true(wait_out(&a, updates_above, 50, false));
	/* published every cycle: the state segment follows the updates */
	before = state_of(arflex_host_state(&a));
	assert_true(before >= 50);
	assert_true(wait_out(&a, state_above, before + 20, false));
	assert_true(state_of(arflex_host_state(&a)) > before);

	/* ADOPT before START, then START: the newest value of a's segment, once */
	assert_int_equal(arflex_host_adopt(&b, arflex_host_state(&a)->name, T_CALL), 0);
	before = state_of(arflex_host_state(&a));
	assert_int_equal(arflex_host_start(&b, T_CALL), 0);
	assert_true(wait_out(&b, updates_above, 5, false));
	assert_true(read_out(&b, &o));
	assert_int_equal(o.adopt_calls, 1);
	assert_true(o.adopted >= before);                 /* the newest value at b's START */
	assert_true(o.adopted <= state_of(arflex_host_state(&a)));
	/* b continues from it: its first update already counted on from the adopted value */
	assert_true(o.state_value == o.adopted + o.updates);
	assert_int_equal(arflex_host_adopt(&b, arflex_host_state(&a)->name, T_CALL), -EBUSY);
	/* once: a later START does not adopt again */
	assert_int_equal(arflex_host_stop(&b, T_CALL), 0);
	assert_int_equal(arflex_host_start(&b, T_CALL), 0);
	assert_true(wait_out(&b, updates_above, o.updates + 5, false));
	assert_true(read_out(&b, &o));
	assert_int_equal(o.adopt_calls, 1);
	assert_int_equal(arflex_host_stop(&b, T_CALL), 0);

	/* errors: no such segment; a declared conversion; a type the hook refuses */
	snprintf(missing, sizeof(missing), "/arflex.%s.none.state", rid);
	assert_int_equal(arflex_host_adopt(&b, missing, T_CALL), -ENOENT);
	snprintf(old_name, sizeof(old_name), "/arflex.%s.older.state", rid);
	assert_int_equal(arflex_port_create(&old, old_name, &old_spec), 0);
	v = 7;
	assert_int_equal(arflex_state_write(&old, &v, sizeof(v)), 0);
	probe_state = true;
	assert_int_equal(probe_host(&c, "2-old", 0, 0, true), 0);
	probe_state = false;
	spawn_ready(&c);
	assert_int_equal(arflex_host_adopt(&c, old_name, T_CALL), 0);
	assert_int_equal(arflex_host_start(&c, T_CALL), 0);
	assert_true(wait_out(&c, adopted_is, 70, false)); /* test.OldProbeState 0.3: x 10 */
	assert_int_equal(arflex_host_stop(&c, T_CALL), 0);
	assert_int_equal(arflex_port_destroy(&old), 0);
	assert_int_equal(arflex_port_create(&old, old_name, &other_spec), 0);
	assert_int_equal(arflex_state_write(&old, &v, sizeof(v)), 0);
	assert_int_equal(arflex_host_adopt(&c, old_name, T_CALL), 0);
	assert_int_equal(arflex_host_start(&c, T_CALL), -EPROTOTYPE);
	assert_int_equal(arflex_ctl_state(c.ctl), ARFLEX_STATE_READY);
	assert_int_equal(arflex_port_destroy(&old), 0);

	shutdown_ok(&a);
	shutdown_ok(&b);
	shutdown_ok(&c);
	arflex_host_destroy(&a);
	arflex_host_destroy(&b);
	arflex_host_destroy(&c);
	unlink(logpath);
	th_assert_clean(rid);
}

/* D57: arflex_component_adopt_prepare: the hook runs at the ADOPT with the value published
 * then; the START still adopts the newest value, also when nothing was published after the
 * ADOPT (the hook's read does not consume it); a refusing hook refuses the ADOPT and nothing is
 * adopted. */
static void adopt_prepare_runs_at_the_adopt(void **state)
{
	struct arflex_host a, b, c;
	struct probe_out o;
	uint64_t at_adopt;

	(void)state;
	setup_ids("prep");
	make_env("ARFLEX_PROBE_PREPARE=count");
	probe_state = true;
	assert_int_equal(probe_host(&a, "old", 0, 0, true), 0);
	assert_int_equal(probe_host(&b, "1-old", 0, 0, true), 0);
	assert_int_equal(probe_host(&c, "2-old", 0, 0, true), 0);
	probe_state = false;
	spawn_ready(&a);
	spawn_ready(&b);
	assert_int_equal(arflex_host_start(&a, T_CALL), 0);
	assert_true(wait_out(&a, updates_above, 50, false));
	assert_int_equal(arflex_host_stop(&a, T_CALL), 0); /* nothing published after this */
	at_adopt = state_of(arflex_host_state(&a));
	assert_int_equal(arflex_host_adopt(&b, arflex_host_state(&a)->name, T_CALL), 0);
	assert_int_equal(arflex_host_start(&b, T_CALL), 0);
	assert_true(wait_out(&b, updates_above, 5, false));
	assert_true(read_out(&b, &o));
	assert_int_equal(o.prepare_calls, 1);
	assert_int_equal(o.prepared, at_adopt);
	assert_int_equal(o.adopt_calls, 1); /* the same value, taken again at the START */
	assert_int_equal(o.adopted, at_adopt);
	assert_int_equal(arflex_host_stop(&b, T_CALL), 0);

	make_env("ARFLEX_PROBE_PREPARE=refuse");
	spawn_ready(&c);
	assert_int_equal(arflex_host_adopt(&c, arflex_host_state(&a)->name, T_CALL), -EBADMSG);
	assert_int_equal(arflex_host_start(&c, T_CALL), 0);
	assert_true(wait_out(&c, updates_above, 5, false));
	assert_true(read_out(&c, &o));
	assert_int_equal(o.adopt_calls, 0);
	assert_int_equal(o.prepare_calls, 0);

	shutdown_ok(&a);
	shutdown_ok(&b);
	shutdown_ok(&c);
	arflex_host_destroy(&a);
	arflex_host_destroy(&b);
	arflex_host_destroy(&c);
	unlink(logpath);
	th_assert_clean(rid);
}

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
		cmocka_unit_test(params_applied_at_cycle_boundary),
		cmocka_unit_test(safe_when_heartbeat_stops),
		cmocka_unit_test(moves_hardware_needs_operator_reset),
		cmocka_unit_test(component_requires_reset),
		cmocka_unit_test(failing_configure_leaves_nothing),
		cmocka_unit_test(failing_start_is_refused),
		cmocka_unit_test(bind_and_unbind_while_running),
		cmocka_unit_test(state_published_and_adopted_once),
		cmocka_unit_test(adopt_prepare_runs_at_the_adopt),
		cmocka_unit_test(sigterm_stops_cleanly),
		cmocka_unit_test(killed_mid_cycle_leaves_nothing),
		cmocka_unit_test(restart_reuses_objects_and_waits_for_reset),
		cmocka_unit_test(scheduling_applied_or_warned),
		cmocka_unit_test(bad_command_line),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
