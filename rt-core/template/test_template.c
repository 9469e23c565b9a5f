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

static int case_ported(const char *exe, const char *contract_path)
{
	struct arflex_host_opts o;
	struct arflex_port vel;
	struct arflex_sample v, u;
	bool vel_open = false;
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
	CHECK(arflex_host_start(&h, CALL_TIMEOUT) == 0, "START");
	/* 1500 cycles of 1 ms: the closed loop settles to 1e-6 in ~1000. */
	CHECK(wait_seq(&vel, 1500, &v) == 0, "no 1500 cycles");
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
	bool ported;

	ported = argc == 4 && strcmp(argv[1], "ported") == 0;
	if (!ported && (argc != 3 || strcmp(argv[1], "template"))) {
		fprintf(stderr, "usage: %s ported <component executable> <contract.xml>\n"
			"       %s template <component executable>\n", argv[0], argv[0]);
		return 2;
	}
	snprintf(rid, sizeof(rid), "t-tpl-%ld", (long)getpid());
	if (ported)
		case_ported(argv[2], argv[3]);
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
