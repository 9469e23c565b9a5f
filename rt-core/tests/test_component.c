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

#define SEC 1000000000ull
#define T_CALL (5 * SEC)

extern char **environ;

struct probe_out {
	uint64_t updates, safe_calls, safe_firsts;
	int64_t gain;
	uint64_t torn, in_value, in_reads, in_bound, in_binding;
};

static const struct arflex_port_type value_type = { "test.Value", 1, 0, sizeof(uint64_t) };

static char rid[64];
static char logpath[128];
static char *envp[256];
static char env_log[200];

static void make_env(const char *extra)
{
	int n = 0;

	snprintf(env_log, sizeof(env_log), "ARFLEX_PROBE_LOG=%s", logpath);
	for (char **e = environ; *e && n < 250; e++)
		if (strncmp(*e, "ARFLEX_", 7))
			envp[n++] = *e;
	envp[n++] = env_log;
	if (extra)
		envp[n++] = (char *)extra;
	envp[n] = NULL;
}

static void setup_ids(const char *tag)
{
	th_rid(rid, sizeof(rid), tag);
	snprintf(logpath, sizeof(logpath), "/tmp/arflex-probe-%s.log", rid);
	unlink(logpath);
	make_env(NULL);
}

static int probe_prio; /* priority, CPU mask and orphan hold for the next probe_host */
static uint64_t probe_cpus;
static uint64_t probe_hold;

static int probe_host(struct arflex_host *h, const char *inst, uint64_t hb_timeout,
		      uint32_t cfg_flags, bool with_out)
{
	struct arflex_param_slot p[2];
	struct arflex_host_output out = {
		.port = "out",
		.spec = { .method = ARFLEX_PORT_STATE,
			  .type = { "test.ProbeOut", 1, 0, sizeof(struct probe_out) } },
	};
	struct arflex_host_opts o = {
		.runtime = rid, .instance = inst,
		.config = { .period_ns = 1000000, .hb_timeout_ns = hb_timeout,
			    .cfg_flags = cfg_flags | ARFLEX_CFG_NO_MLOCK | ARFLEX_CFG_NO_DMA_LATENCY,
			    .priority = probe_prio, .cpu_mask = probe_cpus,
			    .orphan_hold_ns = probe_hold },
		.params = p, .nparams = 2, .outputs = &out, .noutputs = with_out ? 1 : 0,
	};

	th_track(rid, inst);
	memset(p, 0, sizeof(p));
	strcpy(p[0].name, "gain");
	p[0].type = ARFLEX_PARAM_INT64;
	p[0].flags = ARFLEX_PARAM_MUTABLE;
	p[0].min_bits = (uint64_t)-1000;
	p[0].max_bits = 1000;
	p[0].default_bits = 1;
	strcpy(p[1].name, "scale");
	p[1].type = ARFLEX_PARAM_DOUBLE;
	p[1].min_bits = arflex_f64_bits(0.0);
	p[1].max_bits = arflex_f64_bits(10.0);
	p[1].default_bits = arflex_f64_bits(1.0);
	return arflex_host_create(h, &o);
}

static bool read_out(struct arflex_host *h, struct probe_out *o)
{
	struct arflex_port *p = arflex_host_output(h, "out");

	for (int i = 0; i < 1000; i++) {
		p->last_seq = 0;
		if (arflex_state_read(p, o, sizeof(*o), NULL) == 1)
			return true;
		if (!__atomic_load_n(&p->hdr->head, __ATOMIC_ACQUIRE))
			return false;
	}
	return false;
}

typedef bool (*pred_fn)(const struct probe_out *o, uint64_t arg);

/* Waits (with a deadline, not a sleep) until @pred holds on the probe's output; keeps the
 * runtime heartbeat fresh when @hb. Dumps the last output on expiry. */
static bool wait_out(struct arflex_host *h, pred_fn pred, uint64_t arg, bool hb)
{
	uint64_t deadline = arflex_sys_now_ns() + 10 * SEC;
	struct probe_out o = { 0 };

	while (arflex_sys_now_ns() < deadline) {
		if (hb)
			arflex_host_heartbeat(h);
		if (read_out(h, &o) && pred(&o, arg))
			return true;
		arflex_sys_sleep_until(arflex_sys_now_ns() + 1000000);
	}
	fprintf(stderr, "wait_out expired: updates %llu safe %llu gain %lld in %llu bound %llu\n",
		(unsigned long long)o.updates, (unsigned long long)o.safe_calls,
		(long long)o.gain, (unsigned long long)o.in_value,
		(unsigned long long)o.in_bound);
	return false;
}

static bool updates_above(const struct probe_out *o, uint64_t n) { return o->updates > n; }
static bool safe_above(const struct probe_out *o, uint64_t n) { return o->safe_calls > n; }
static bool gain_is(const struct probe_out *o, uint64_t g) { return o->gain == (int64_t)g; }
static bool in_is(const struct probe_out *o, uint64_t v) { return o->in_value == v; }
static bool unbound(const struct probe_out *o, uint64_t v) { (void)v; return !o->in_bound; }
static bool binding_is(const struct probe_out *o, uint64_t b) { return o->in_binding == b; }
static uint64_t binding_of(struct arflex_host *h)
{
	struct probe_out o;

	assert_true(read_out(h, &o));
	return o.in_binding;
}

static void spawn_ready(struct arflex_host *h)
{
	assert_int_equal(arflex_host_spawn(h, ARFLEX_PROBE_EXE, NULL, envp), 0);
	assert_int_equal(arflex_host_wait_state(h, ARFLEX_STATE_READY, 10 * SEC), 0);
}

static void shutdown_ok(struct arflex_host *h)
{
	assert_int_equal(arflex_host_shutdown(h, T_CALL), 0);
	assert_int_equal(arflex_host_wait_exit(h, 10 * SEC), 0);
	assert_true(WIFEXITED(arflex_host_exit_status(h)));
	assert_int_equal(WEXITSTATUS(arflex_host_exit_status(h)), 0);
	assert_int_equal(arflex_ctl_state(h->ctl), ARFLEX_STATE_EXITED);
}

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

/* Waits (with a deadline) until every bit of @bits is set in the control block's flags. */
static bool wait_flags(struct arflex_host *h, uint32_t bits, uint64_t timeout_ns)
{
	uint64_t deadline = arflex_sys_now_ns() + timeout_ns;

	while (arflex_sys_now_ns() < deadline) {
		if ((arflex_ctl_flags(h->ctl) & bits) == bits)
			return true;
		arflex_sys_sleep_until(arflex_sys_now_ns() + 200000);
	}
	fprintf(stderr, "wait_flags expired: flags 0x%x, want 0x%x\n", arflex_ctl_flags(h->ctl),
		bits);
	return false;
}

/* Issue 15, finding 2: the supervisor dies (its end of the stdin pipe closes, and nobody reads
 * the half's output any more). The half goes safe within a cycle, does not die of SIGPIPE when
 * it says so, holds for the contract's orphan hold, then exits 0 and removes its objects. */
static void supervisor_lost_holds_then_leaves_nothing(void **state)
{
	const uint64_t hold = 1000 * 1000000ull;
	struct arflex_host h;
	struct probe_out o;
	uint64_t t_drop, t_exit;
	char log[256];

	(void)state;
	setup_ids("orphan");
	probe_hold = hold;
	assert_int_equal(probe_host(&h, "arm", 0, ARFLEX_CFG_MOVES_HARDWARE, true), 0);
	probe_hold = 0;
	assert_int_equal(arflex_host_spawn_ex(&h, ARFLEX_PROBE_EXE, NULL, envp,
					      ARFLEX_HOST_SUPERVISOR_PIPE |
					      ARFLEX_HOST_OUTPUT_PIPE), 0);
	assert_int_equal(arflex_host_wait_state(&h, ARFLEX_STATE_READY, 10 * SEC), 0);
	assert_true(h.ctl->config.cfg_flags & ARFLEX_CFG_SUPERVISOR_PIPE);
	assert_int_equal(arflex_host_start(&h, T_CALL), 0);
	assert_true(wait_out(&h, updates_above, 5, false));
	assert_false(arflex_ctl_flags(h.ctl) & ARFLEX_FLAG_SAFE_ACTIVE);

	/* kill -9 of the supervisor, as the half sees it */
	arflex_host_close_output(&h);
	t_drop = arflex_sys_now_ns();
	arflex_host_drop_supervisor(&h);
	assert_true(wait_flags(&h, ARFLEX_FLAG_SUPERVISOR_LOST | ARFLEX_FLAG_SAFE_ACTIVE |
				   ARFLEX_FLAG_RESET_REQUIRED, 2 * SEC));
	/* it holds: alive, calling its safe hook, no update */
	assert_true(read_out(&h, &o));
	assert_true(wait_out(&h, safe_above, o.safe_calls + 10, false));
	assert_true(arflex_sys_now_ns() - t_drop < hold); /* else the machine is too slow */
	assert_int_equal(arflex_host_wait_exit(&h, 0), -ETIMEDOUT);
	assert_int_equal(arflex_host_reset(&h, T_CALL), -EAGAIN); /* no reset for an orphan */
	/* then it leaves, cleanly, after the hold */
	assert_int_equal(arflex_host_wait_exit(&h, 10 * SEC), 0);
	t_exit = arflex_sys_now_ns();
	assert_true(t_exit - t_drop >= hold);
	assert_true(WIFEXITED(arflex_host_exit_status(&h)));
	assert_int_equal(WEXITSTATUS(arflex_host_exit_status(&h)), 0);
	assert_int_equal(arflex_ctl_state(h.ctl), ARFLEX_STATE_EXITED);
	/* and removed its ctl, queues and output segment itself */
	assert_int_equal(th_leftovers(rid), 0);
	arflex_host_destroy(&h);
	assert_true(th_read_file(logpath, log, sizeof(log)) > 0);
	assert_string_equal(log, "configure\nstart\nupdate\nstop\ncleanup\n");
	unlink(logpath);
	th_assert_clean(rid);

	/* a hold of 0, not running: leaves at once */
	setup_ids("orphan0");
	assert_int_equal(probe_host(&h, "probe", 0, 0, true), 0);
	assert_int_equal(arflex_host_spawn_ex(&h, ARFLEX_PROBE_EXE, NULL, envp,
					      ARFLEX_HOST_SUPERVISOR_PIPE), 0);
	assert_int_equal(arflex_host_wait_state(&h, ARFLEX_STATE_READY, 10 * SEC), 0);
	arflex_host_drop_supervisor(&h);
	assert_int_equal(arflex_host_wait_exit(&h, 10 * SEC), 0);
	assert_int_equal(WEXITSTATUS(arflex_host_exit_status(&h)), 0);
	assert_int_equal(arflex_ctl_state(h.ctl), ARFLEX_STATE_EXITED);
	assert_true(arflex_ctl_flags(h.ctl) & ARFLEX_FLAG_SUPERVISOR_LOST);
	assert_true(arflex_ctl_flags(h.ctl) & ARFLEX_FLAG_SAFE_ACTIVE);
	assert_int_equal(th_leftovers(rid), 0);
	arflex_host_destroy(&h);
	unlink(logpath);
	th_assert_clean(rid);
}

/* A half whose output pipe lost its reader logs ("safe mode entered") and lives on. */
static void closed_output_pipe_does_not_kill(void **state)
{
	struct arflex_host h;
	uint64_t deadline;

	(void)state;
	setup_ids("sigpipe");
	assert_int_equal(probe_host(&h, "probe", 100000000, 0, true), 0);
	assert_int_equal(arflex_host_spawn_ex(&h, ARFLEX_PROBE_EXE, NULL, envp,
					      ARFLEX_HOST_OUTPUT_PIPE), 0);
	assert_int_equal(arflex_host_wait_state(&h, ARFLEX_STATE_READY, 10 * SEC), 0);
	assert_true(arflex_host_output_fd(&h) >= 0);
	arflex_host_close_output(&h);
	assert_int_equal(arflex_host_output_fd(&h), -1);
	arflex_host_heartbeat(&h);
	assert_int_equal(arflex_host_start(&h, T_CALL), 0);
	/* no heartbeat: safe mode, counted, then reported on stderr by the mailbox thread */
	deadline = arflex_sys_now_ns() + 10 * SEC;
	while (__atomic_load_n(&h.ctl->warnings[ARFLEX_WARN_SAFE], __ATOMIC_ACQUIRE) == 0 &&
	       arflex_sys_now_ns() < deadline)
		arflex_sys_sleep_until(arflex_sys_now_ns() + 1000000);
	assert_true(h.ctl->warnings[ARFLEX_WARN_SAFE] >= 1);
	/* two round trips: the serve loop reported (wrote to the dead pipe) in between */
	assert_int_equal(arflex_host_call(&h, ARFLEX_CMD_PING, NULL, NULL, T_CALL), 0);
	assert_int_equal(arflex_host_call(&h, ARFLEX_CMD_PING, NULL, NULL, T_CALL), 0);
	assert_int_equal(arflex_host_wait_exit(&h, 0), -ETIMEDOUT);
	arflex_host_heartbeat(&h);
	shutdown_ok(&h);
	assert_true(WIFEXITED(arflex_host_exit_status(&h)));
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
		cmocka_unit_test(sigterm_stops_cleanly),
		cmocka_unit_test(killed_mid_cycle_leaves_nothing),
		cmocka_unit_test(restart_reuses_objects_and_waits_for_reset),
		cmocka_unit_test(scheduling_applied_or_warned),
		cmocka_unit_test(bad_command_line),
		cmocka_unit_test(supervisor_lost_holds_then_leaves_nothing),
		cmocka_unit_test(closed_output_pipe_does_not_kill),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
