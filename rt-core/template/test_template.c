/*
 * test_template - CTest rt.template.*: the ported PI loop (ported/pi_velocity.c) run as a
 * component under the rt-core host API.
 *
 *   test_template ported <arflex-pi-velocity exe> <bundle/pi-velocity.xml>
 *     load the component's contract (arflex_host_load_contract): its ports, parameters and
 *     timing are declared there and nowhere in this file; create control block, queues and
 *     ports from it; spawn; START; wait (condition with deadline)
 *     until N cycles and check the plant converged to the setpoint; change the setpoint with
 *     SET_PARAM and check it converges again; SHUTDOWN; check the exit status and that no
 *     shared object, queue or child process is left.
 *     Every value it publishes in its first 1500 cycles that the test reads (seq = cycle + 1)
 *     is the legacy loop's after as many cycles, bit for bit (trace_legacy.c), and the two
 *     loops' steps (trace_legacy.c, trace_ported.c) agree cycle by cycle over 3000 cycles with
 *     a setpoint step that saturates the actuator.
 *   test_template legacy <legacy-pi-velocity exe>
 *     the legacy program for 1500 cycles: it exits 0, and each velocity it prints (every 500
 *     cycles and at the end) is the one its own step computes in trace_legacy.c.
 *   test_template template <arflex-template exe>
 *     the skeleton (template.c): bind its input `in` to a provider segment made by the test,
 *     write values there, check out = gain * in with the input's seq; SHUTDOWN; nothing left.
 */
#define _GNU_SOURCE
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <mqueue.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "arflex/host.h"
#include "arflex/host_contract.h"
#include "arflex_types/sample.h"
#include "helper.h" /* rt-core test kit: leak checks */
#include "trace.h"

#define SEC UINT64_C(1000000000)
#define MS UINT64_C(1000000)
#define CALL_TIMEOUT (2 * SEC)
#define WAIT_TIMEOUT (15 * SEC)

static const struct arflex_port_type sample_type = { "arflex.Sample", 1, 0, 24 };
/* The port types this harness was compiled with, for the contracts it loads. */
static const struct arflex_host_type types[] = { ARFLEX_HOST_TYPE(SAMPLE) };
static struct arflex_host_contract contract;

static char rid[ARFLEX_ID_MAX + 1];
static struct arflex_host h;
static struct arflex_port provider; /* template case: the input's provider segment */
static bool provider_ok;
static int failures;

#define CHECK(cond, ...)                                                                   \
	do {                                                                               \
		if (!(cond)) {                                                             \
			fprintf(stderr, "FAIL %s:%d: %s: ", __FILE__, __LINE__, #cond);    \
			fprintf(stderr, __VA_ARGS__);                                      \
			fputc('\n', stderr);                                               \
			failures++;                                                        \
			goto out;                                                          \
		}                                                                          \
	} while (0)

static struct arflex_param_slot param_f64(const char *name, double def, double lo, double hi)
{
	struct arflex_param_slot s;

	memset(&s, 0, sizeof(s));
	snprintf(s.name, sizeof(s.name), "%s", name);
	s.type = ARFLEX_PARAM_DOUBLE;
	s.flags = ARFLEX_PARAM_MUTABLE;
	s.min_bits = arflex_f64_bits(lo);
	s.max_bits = arflex_f64_bits(hi);
	s.default_bits = arflex_f64_bits(def);
	return s;
}

static struct arflex_ctl_config config(void)
{
	struct arflex_ctl_config c;

	memset(&c, 0, sizeof(c));
	c.period_ns = 1 * MS;
	c.safe_mode = ARFLEX_SAFE_ZERO;
	c.cfg_flags = ARFLEX_CFG_NO_MLOCK | ARFLEX_CFG_NO_DMA_LATENCY;
	return c;
}

/* Waits until the port's value has seq >= @min_seq; returns it in *@v. */
static int wait_seq(struct arflex_port *p, uint64_t min_seq, struct arflex_sample *v)
{
	uint64_t deadline = arflex_sys_now_ns() + WAIT_TIMEOUT;
	struct arflex_sample s;

	while (arflex_sys_now_ns() < deadline) {
		if (arflex_state_read(p, &s, sizeof(s), NULL) == 1 && s.seq >= min_seq) {
			*v = s;
			return 0;
		}
		if (h.pid && arflex_ctl_state(h.ctl) != ARFLEX_STATE_RUNNING)
			return -ECHILD;
	}
	return -ETIMEDOUT;
}

/* The legacy loop's parameters and command (its constants; the contract's defaults). */
static const struct trace_inputs LEGACY_INPUTS = { 1.0, 15.0, 1.0, 1L << 40, 1.0 };
#define TRACE_N 3000
static struct trace_step legacy_steps[TRACE_N], ported_steps[TRACE_N];

/*
 * As wait_seq, and every value read on the way whose seq is within the legacy trace must be
 * the legacy loop's after seq cycles (its velocity, or its command when @command), bit for
 * bit. *@compared counts the values compared.
 */
static int wait_seq_as_legacy(struct arflex_port *p, uint64_t min_seq, struct arflex_sample *v,
			      bool command, long *compared)
{
	uint64_t deadline = arflex_sys_now_ns() + WAIT_TIMEOUT;
	uint64_t last = 0;
	struct arflex_sample s;

	while (arflex_sys_now_ns() < deadline) {
		if (arflex_state_read(p, &s, sizeof(s), NULL) == 1) {
			if (s.seq != last && s.seq >= 1 && s.seq <= TRACE_N) {
				const struct trace_step *t = &legacy_steps[s.seq - 1];
				double want = command ? t->u : t->velocity;

				last = s.seq;
				(*compared)++;
				if (s.value != want) {
					fprintf(stderr, "FAIL: the ported loop's %s at seq %llu is %.17g, the legacy "
						"loop's after %llu cycles %.17g\n", command ? "command" : "velocity",
						(unsigned long long)s.seq, s.value, (unsigned long long)s.seq, want);
					return -EDOM;
				}
			}
			if (s.seq >= min_seq) {
				*v = s;
				return 0;
			}
		}
		if (h.pid && arflex_ctl_state(h.ctl) != ARFLEX_STATE_RUNNING)
			return -ECHILD;
	}
	return -ETIMEDOUT;
}

/* The two loops' steps, cycle by cycle on the same inputs: 0 when every one agrees. */
static int compare_steps(uint64_t period_ns)
{
	/* setpoint 1, then 9 rad/s from cycle 1500: the actuator saturates (U_MAX 5) on the way */
	const struct trace_inputs in = { 1.0, 15.0, 1.0, 1500, 9.0 };

	trace_legacy(TRACE_N, &in, legacy_steps);
	trace_ported(TRACE_N, &in, period_ns, ported_steps);
	for (long i = 0; i < TRACE_N; i++) {
		if (legacy_steps[i].velocity != ported_steps[i].velocity ||
		    legacy_steps[i].u != ported_steps[i].u ||
		    legacy_steps[i].saturated != ported_steps[i].saturated) {
			fprintf(stderr, "FAIL: cycle %ld: legacy velocity %.17g u %.17g saturations %ld, "
				"ported velocity %.17g u %.17g saturations %ld\n", i,
				legacy_steps[i].velocity, legacy_steps[i].u, legacy_steps[i].saturated,
				ported_steps[i].velocity, ported_steps[i].u, ported_steps[i].saturated);
			return -1;
		}
	}
	if (legacy_steps[TRACE_N - 1].saturated == 0) {
		fprintf(stderr, "FAIL: the compared cycles never saturated the actuator\n");
		return -1;
	}
	printf("rt.template: the ported loop's step equals the legacy one's in all %d cycles "
	       "(%ld saturated)\n", TRACE_N, legacy_steps[TRACE_N - 1].saturated);
	return 0;
}

static int case_legacy(const char *exe)
{
	char cmd[1024], line[256];
	long compared = 0, n;
	double vel;
	bool done = false;
	FILE *f;
	int st;

	trace_legacy(TRACE_N, &LEGACY_INPUTS, legacy_steps);
	snprintf(cmd, sizeof(cmd), "'%s' 1500", exe);
	f = popen(cmd, "r");
	CHECK(f != NULL, "popen %s: %s", cmd, strerror(errno));
	while (fgets(line, sizeof(line), f)) {
		char want[64], got[64];
		long at;

		if (sscanf(line, "cycle %ld: velocity %63s", &n, got) == 2)
			at = n; /* printed after the step of cycle n */
		else if (sscanf(line, "done after %ld cycles: velocity %63s", &n, got) == 2)
			at = n - 1, done = true;
		else
			continue;
		CHECK(at >= 0 && at < TRACE_N, "line out of the trace: %s", line);
		snprintf(want, sizeof(want), "%.6f", legacy_steps[at].velocity);
		CHECK(strcmp(want, got) == 0, "the legacy program printed velocity %s where its step "
		      "gives %s: %s", got, want, line);
		compared++;
	}
	st = pclose(f);
	CHECK(WIFEXITED(st) && WEXITSTATUS(st) == 0, "the legacy program's exit status %#x", st);
	CHECK(done && compared == 4, "%ld velocities compared, the final line %s", compared,
	      done ? "seen" : "missing");
	vel = legacy_steps[1499].velocity;
	CHECK(fabs(vel - 1.0) < 1e-3, "velocity %.6f after 1500 cycles, setpoint 1", vel);
out:
	return 0;
}

static int case_ported(const char *exe, const char *contract_path)
{
	struct arflex_host_opts o;
	struct arflex_port vel;
	struct arflex_sample v, u;
	bool vel_open = false;
	long compared = 0;
	uint64_t applied;
	char err[512];
	int st;

	/* Ports velocity and command, parameters kp, ki and setpoint with their defaults and
	 * ranges, the 1 ms period, the safe mode: all from the bundle's contract. */
	CHECK(arflex_host_load_contract(&contract, contract_path, types, 1, err,
					sizeof(err)) == 0, "%s", err);
	arflex_host_contract_opts(&contract, rid, "pi", &o);
	/* The harness's own choices on a shared machine: no mlockall, no cpu_dma_latency, and no
	 * heartbeat watchdog (this test does not write the runtime heartbeat while it waits). */
	o.config.cfg_flags |= ARFLEX_CFG_NO_MLOCK | ARFLEX_CFG_NO_DMA_LATENCY;
	o.config.hb_timeout_ns = 0;
	CHECK(arflex_host_create(&h, &o) == 0, "create");
	CHECK(arflex_host_spawn(&h, exe, NULL, NULL) == 0, "spawn %s", exe);
	CHECK(arflex_host_wait_state(&h, ARFLEX_STATE_READY, WAIT_TIMEOUT) == 0, "READY");
	CHECK(arflex_port_open(&vel, arflex_host_output_name(&h, "velocity"), false, false,
			       ARFLEX_PORT_STATE, &sample_type) == 0, "open velocity");
	vel_open = true;
	CHECK(compare_steps(o.config.period_ns) == 0, "the ported loop's step is not the legacy one's");
	trace_legacy(TRACE_N, &LEGACY_INPUTS, legacy_steps);
	CHECK(arflex_host_start(&h, CALL_TIMEOUT) == 0, "START");
	/* 1500 cycles of 1 ms: the closed loop settles to 1e-6 in ~1000; each value read on the
	 * way is the legacy loop's of the same cycle */
	CHECK(wait_seq_as_legacy(&vel, 1500, &v, false, &compared) == 0, "no 1500 cycles as the legacy loop's");
	CHECK(compared >= 10, "only %ld values of the ported loop read to compare", compared);
	printf("rt.template.ported: %ld values of its first 1500 cycles read, each the legacy loop's\n",
	       compared);
	CHECK(fabs(v.value - 1.0) < 1e-3, "velocity %.6f after %llu cycles, setpoint 1",
	      v.value, (unsigned long long)v.seq);
	CHECK(arflex_state_read(arflex_host_output(&h, "command"), &u, sizeof(u), NULL) >= 0,
	      "read command");
	CHECK(fabs(u.value - 0.5) < 1e-2, "command %.6f, expected ~0.5 (setpoint / plant gain)",
	      u.value);
	/* A new setpoint through SET_PARAM: applied at a cycle boundary, the loop follows. */
	CHECK(arflex_host_set_param(&h, "setpoint", arflex_f64_bits(-0.5), &applied,
				    CALL_TIMEOUT) == 0, "SET_PARAM setpoint");
	CHECK(arflex_bits_f64(applied) == -0.5, "applied %g", arflex_bits_f64(applied));
	CHECK(wait_seq(&vel, v.seq + 1500, &v) == 0, "no 1500 more cycles");
	CHECK(fabs(v.value + 0.5) < 1e-3, "velocity %.6f, setpoint -0.5", v.value);
	CHECK(arflex_host_shutdown(&h, CALL_TIMEOUT) == 0, "SHUTDOWN");
	CHECK(arflex_host_wait_exit(&h, WAIT_TIMEOUT) == 0, "exit");
	st = arflex_host_exit_status(&h);
	CHECK(WIFEXITED(st) && WEXITSTATUS(st) == 0, "exit status %#x", st);
out:
	if (vel_open)
		arflex_port_close(&vel);
	return 0;
}

static int case_template(const char *exe)
{
	struct arflex_param_slot p[1] = { param_f64("gain", 3.0, -10.0, 10.0) };
	struct arflex_host_output outs[1] = {
		{ "out", { .method = ARFLEX_PORT_STATE, .type = sample_type, .depth = 1 } },
	};
	struct arflex_host_opts o = {
		.runtime = rid, .instance = "tpl", .config = config(),
		.params = p, .nparams = 1, .outputs = outs, .noutputs = 1,
	};
	struct arflex_port_spec spec = { .method = ARFLEX_PORT_STATE, .type = sample_type,
					 .depth = 1 };
	struct arflex_port out;
	bool out_open = false;
	char name[ARFLEX_OBJ_NAME_SIZE];
	int st;

	CHECK(arflex_ctl_obj_name(name, sizeof(name), rid, "src", "out.value") == 0, "name");
	CHECK(arflex_port_create(&provider, name, &spec) == 0, "provider segment");
	provider_ok = true;
	CHECK(arflex_host_create(&h, &o) == 0, "create");
	CHECK(arflex_host_spawn(&h, exe, NULL, NULL) == 0, "spawn %s", exe);
	CHECK(arflex_host_wait_state(&h, ARFLEX_STATE_READY, WAIT_TIMEOUT) == 0, "READY");
	CHECK(arflex_port_open(&out, arflex_host_output_name(&h, "out"), false, false,
			       ARFLEX_PORT_STATE, &sample_type) == 0, "open out");
	out_open = true;
	CHECK(arflex_host_bind(&h, "in", name, CALL_TIMEOUT) == 0, "BIND in");
	CHECK(arflex_host_start(&h, CALL_TIMEOUT) == 0, "START");
	for (uint64_t i = 1; i <= 20; i++) {
		struct arflex_sample in = { i, (int64_t)arflex_sys_now_ns(), 0.25 * (double)i }, got;

		CHECK(arflex_state_write(&provider, &in, sizeof(in)) == 0, "write in");
		CHECK(wait_seq(&out, i, &got) == 0, "no output for input %llu",
		      (unsigned long long)i);
		CHECK(got.seq == i && got.value == 3.0 * in.value, "out seq %llu value %g for in "
		      "%g", (unsigned long long)got.seq, got.value, in.value);
	}
	CHECK(arflex_host_shutdown(&h, CALL_TIMEOUT) == 0, "SHUTDOWN");
	CHECK(arflex_host_wait_exit(&h, WAIT_TIMEOUT) == 0, "exit");
	st = arflex_host_exit_status(&h);
	CHECK(WIFEXITED(st) && WEXITSTATUS(st) == 0, "exit status %#x", st);
out:
	if (out_open)
		arflex_port_close(&out);
	return 0;
}

static bool leaked(const char *inst)
{
	/* /dev/mqueue may not be mounted: the kit also probes the tracked queues by name. */
	th_track(rid, inst);
	return th_leftovers(rid) > 0 || !th_no_children();
}

int main(int argc, char **argv)
{
	bool ported, legacy;

	ported = argc == 4 && strcmp(argv[1], "ported") == 0;
	legacy = argc == 3 && strcmp(argv[1], "legacy") == 0;
	if (!ported && !legacy && (argc != 3 || strcmp(argv[1], "template"))) {
		fprintf(stderr, "usage: %s ported <component executable> <contract.xml>\n"
			"       %s legacy <legacy-pi-velocity executable>\n"
			"       %s template <component executable>\n", argv[0], argv[0], argv[0]);
		return 2;
	}
	snprintf(rid, sizeof(rid), "t-tpl-%ld", (long)getpid());
	if (ported)
		case_ported(argv[2], argv[3]);
	else if (legacy)
		case_legacy(argv[2]);
	else
		case_template(argv[2]);
	if (failures)
		fprintf(stderr, "state %u\n", h.ctl ? arflex_ctl_state(h.ctl) : 99u);
	arflex_host_destroy(&h);
	if (provider_ok)
		arflex_port_destroy(&provider);
	if (leaked(ported ? "pi" : "tpl")) {
		fprintf(stderr, "FAIL: objects or children leaked\n");
		failures++;
	}
	if (failures) {
		fprintf(stderr, "rt.template.%s: %d failure(s)\n", argv[1], failures);
		return 1;
	}
	printf("rt.template.%s: ok\n", argv[1]);
	return 0;
}
