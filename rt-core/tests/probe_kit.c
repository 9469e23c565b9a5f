/* The probe fixture of the process-level component tests (probe_kit.h). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#include "helper.h"
#include "probe_kit.h"

extern char **environ;


extern char **environ;


const struct arflex_port_type value_type = { "test.Value", 1, 0, sizeof(uint64_t) };

char rid[64];
char logpath[128];
char *envp[256];
static char env_log[200];

void make_env(const char *extra)
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

void setup_ids(const char *tag)
{
	th_rid(rid, sizeof(rid), tag);
	snprintf(logpath, sizeof(logpath), "/tmp/arflex-probe-%s.log", rid);
	unlink(logpath);
	make_env(NULL);
}

int probe_prio;
uint64_t probe_cpus;
uint64_t probe_hold;
uint32_t probe_task_type;
bool probe_state;
const struct arflex_port_type probe_state_type = { "test.ProbeState", 1, 0, sizeof(uint64_t) };

int probe_host(struct arflex_host *h, const char *inst, uint64_t hb_timeout,
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
			    .orphan_hold_ns = probe_hold, .task_type = probe_task_type },
		.params = p, .nparams = 2, .outputs = &out, .noutputs = with_out ? 1 : 0,
		.state = probe_state ? &probe_state_type : NULL,
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

bool read_out(struct arflex_host *h, struct probe_out *o)
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


bool wait_out(struct arflex_host *h, pred_fn pred, uint64_t arg, bool hb)
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

bool updates_above(const struct probe_out *o, uint64_t n) { return o->updates > n; }
bool safe_above(const struct probe_out *o, uint64_t n) { return o->safe_calls > n; }
bool gain_is(const struct probe_out *o, uint64_t g) { return o->gain == (int64_t)g; }
bool in_is(const struct probe_out *o, uint64_t v) { return o->in_value == v; }
bool unbound(const struct probe_out *o, uint64_t v) { (void)v; return !o->in_bound; }
bool binding_is(const struct probe_out *o, uint64_t b) { return o->in_binding == b; }
uint64_t binding_of(struct arflex_host *h)
{
	struct probe_out o;

	assert_true(read_out(h, &o));
	return o.in_binding;
}

void spawn_ready(struct arflex_host *h)
{
	assert_int_equal(arflex_host_spawn(h, ARFLEX_PROBE_EXE, NULL, envp), 0);
	assert_int_equal(arflex_host_wait_state(h, ARFLEX_STATE_READY, 10 * SEC), 0);
}

void shutdown_ok(struct arflex_host *h)
{
	assert_int_equal(arflex_host_shutdown(h, T_CALL), 0);
	assert_int_equal(arflex_host_wait_exit(h, 10 * SEC), 0);
	assert_true(WIFEXITED(arflex_host_exit_status(h)));
	assert_int_equal(WEXITSTATUS(arflex_host_exit_status(h)), 0);
	assert_int_equal(arflex_ctl_state(h->ctl), ARFLEX_STATE_EXITED);
}

void finish_probes(struct arflex_host *const *hosts, size_t n)
{
	for (size_t i = 0; i < n; i++)
		shutdown_ok(hosts[i]);
	for (size_t i = 0; i < n; i++)
		arflex_host_destroy(hosts[i]);
	unlink(logpath);
	th_assert_clean(rid);
}
