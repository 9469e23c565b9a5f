/*
 * test_tools - CTest tool.*: the fail-safe tool halves (tool-gripper, tool-spindle) as
 * processes under the rt-core host API, their safety input bound to a guard the test owns (a
 * thread that publishes a fresh arflex.SafetyState every millisecond with the mode it is told,
 * or stays silent).
 *   test_tools <unguarded|stop|lost|command_input> <gripper|spindle> <tool executable> <contract>
 * The tool's ports, parameters, safe mode and movesHardware come from its bundle's contract
 * (arflex_host_load_contract, docs/DECISIONS.md D32/D34). The harness's own choices: a 2 ms
 * period, SCHED_OTHER, no mlock or cpu_dma_latency, no heartbeat watchdog, and a safety
 * freshness of 100 ms (the contract's 20 ms would stop the tool whenever this shared machine
 * delays the test's guard thread). The guard and the command script are the test's own
 * providers, not components: their segments are declared here.
 * Each case checks the tool's output (level, status), its hold word (ctl.hold) and its flags
 * (RESET_REQUIRED), and ends with no /dev/shm/arflex.<rid>.*, queue or child left. Waits are
 * conditions with deadlines; "does not move" is observed over a number of the tool's outputs.
 */
#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "arflex/host.h"
#include "arflex/host_contract.h"
#include "arflex/safety_gate.h"
#include "arflex_types/safety_state.h"
#include "arflex_types/sample.h"
#include "arflex_types/tool_state.h"
#include "helper.h"

#define SEC 1000000000ull
#define MS 1000000ull
#define T_CALL (5 * SEC)
#define T_WAIT (30 * SEC)
#define PERIOD (2 * MS) /* the tools' period here (10 ms in the contracts) */
#define MAX_AGE_MS 100.0 /* safety_max_age_ms here (20 ms in the contracts) */
#define STILL 100       /* outputs a held level must stay unchanged for */

static char rid[64];
static int failures;
static bool spindle;
static const char *exe, *contract_xml;
static double rate; /* parameter rate, 1/s: the contract's default */

#define CHECK(c, ...)                                                           \
	do {                                                                    \
		if (!(c)) {                                                     \
			fprintf(stderr, "FAIL %s:%d: %s: ", __FILE__, __LINE__, #c); \
			fprintf(stderr, __VA_ARGS__);                           \
			fputc('\n', stderr);                                    \
			++failures;                                             \
			return;                                                 \
		}                                                               \
	} while (0)

static const struct arflex_port_type tool_t = { ARFLEX_TYPE_TOOL_STATE_NAME, 1, 0,
						 sizeof(struct arflex_tool_state) };
static const struct arflex_port_type safety_t = { ARFLEX_TYPE_SAFETY_STATE_NAME, 1, 0,
						   sizeof(struct arflex_safety_state) };
static const struct arflex_port_type sample_t = { ARFLEX_TYPE_SAMPLE_NAME, 1, 0,
						   sizeof(struct arflex_sample) };

static uint64_t now(void)
{
	return arflex_sys_now_ns();
}

/* ---- the guard ----------------------------------------------------------------------- */

static struct arflex_host guard_h;
static pthread_t guard_th;
static atomic_bool guard_quit, guard_speaks;
static bool guard_running;
static atomic_uint guard_mode;

static void *guard_main(void *arg)
{
	struct arflex_safety_state s;
	struct timespec ts = { 0, 1000000 };

	(void)arg;
	memset(&s, 0, sizeof(s));
	s.power_scale = 1.0;
	s.force_limit = 150;
	while (!atomic_load(&guard_quit)) {
		if (atomic_load(&guard_speaks)) {
			s.t_ns = (int64_t)now();
			s.seq++;
			s.mode = atomic_load(&guard_mode);
			s.power_scale = s.mode == ARFLEX_SAFETY_STATE_MODE_PROTECTIVE_STOP ? 0.1 : 1.0;
			arflex_state_write(arflex_host_output(&guard_h, "safety"), &s, sizeof(s));
		}
		nanosleep(&ts, NULL);
	}
	return NULL;
}

static int guard_create(void)
{
	struct arflex_host_output o = { "safety",
					{ ARFLEX_PORT_STATE, safety_t, 1, ARFLEX_OVERFLOW_NONE } };
	struct arflex_host_opts opts;
	int r;

	memset(&opts, 0, sizeof(opts));
	opts.runtime = rid;
	opts.instance = "guard";
	opts.config.period_ns = MS;
	opts.config.cfg_flags = ARFLEX_CFG_NO_MLOCK | ARFLEX_CFG_NO_DMA_LATENCY;
	opts.outputs = &o;
	opts.noutputs = 1;
	r = arflex_host_create(&guard_h, &opts);
	if (r < 0)
		return r;
	atomic_store(&guard_mode, ARFLEX_SAFETY_STATE_MODE_NORMAL);
	atomic_store(&guard_speaks, false);
	r = -pthread_create(&guard_th, NULL, guard_main, NULL);
	guard_running = r == 0;
	return r;
}

static void guard_destroy(void)
{
	atomic_store(&guard_quit, true);
	if (guard_running)
		pthread_join(guard_th, NULL);
	arflex_host_destroy(&guard_h);
}

/* ---- the tool -------------------------------------------------------------------------- */

static struct arflex_host tool_h;
static struct arflex_port tool_port; /* the consumer's reader of `tool` */
static struct arflex_tool_state last;

/* Creates, spawns and starts the tool as its contract declares it, unguarded. */
static int tool_create(void)
{
	static const struct arflex_host_type types[] = {
		ARFLEX_HOST_TYPE(SAFETY_STATE), ARFLEX_HOST_TYPE(SAMPLE), ARFLEX_HOST_TYPE(TOOL_STATE),
	};
	static struct arflex_host_contract c;
	struct arflex_host_opts opts;
	struct arflex_param_slot *age = NULL, *rt = NULL;
	char err[512];
	int r;

	if ((r = arflex_host_load_contract(&c, contract_xml, types, 3, err, sizeof(err))) < 0)
		return fprintf(stderr, "%s\n", err), r;
	for (unsigned i = 0; i < c.nparams; i++) {
		if (strcmp(c.params[i].name, "safety_max_age_ms") == 0)
			age = &c.params[i];
		else if (strcmp(c.params[i].name, "rate") == 0)
			rt = &c.params[i];
	}
	if (!age || !rt || !(c.config.cfg_flags & ARFLEX_CFG_MOVES_HARDWARE))
		return fprintf(stderr, "%s: no rate/safety_max_age_ms, or not movesHardware\n",
			       contract_xml), -EINVAL;
	age->default_bits = arflex_f64_bits(MAX_AGE_MS);
	rate = arflex_bits_f64(rt->default_bits);
	arflex_host_contract_opts(&c, rid, spindle ? "spindle" : "gripper", &opts);
	opts.config.period_ns = PERIOD;
	opts.config.deadline_ns = PERIOD;
	opts.config.priority = 0;
	opts.config.hb_timeout_ns = 0;
	opts.config.cfg_flags |= ARFLEX_CFG_NO_MLOCK | ARFLEX_CFG_NO_DMA_LATENCY;
	if ((r = arflex_host_create(&tool_h, &opts)) < 0 ||
	    (r = arflex_host_spawn(&tool_h, exe, NULL, NULL)) < 0 ||
	    (r = arflex_host_wait_state(&tool_h, ARFLEX_STATE_READY, 10 * SEC)) < 0)
		return r;
	if ((r = arflex_port_open(&tool_port, arflex_host_output_name(&tool_h, "tool"), false, false,
				  ARFLEX_PORT_STATE, &tool_t)) < 0)
		return r;
	return arflex_host_start(&tool_h, T_CALL);
}

static void tool_destroy(void)
{
	if (tool_port.hdr)
		arflex_port_close(&tool_port);
	if (tool_h.pid > 0 && !tool_h.reaped && arflex_host_shutdown(&tool_h, T_CALL) == 0)
		arflex_host_wait_exit(&tool_h, 5 * SEC);
	arflex_host_destroy(&tool_h);
}

/* The tool's next output into `last`; false at the deadline. */
static bool next(uint64_t deadline)
{
	while (now() < deadline) {
		if (arflex_state_read(&tool_port, &last, sizeof(last), NULL) == 1)
			return true;
		sched_yield();
	}
	return false;
}

static uint32_t hold_cause(void)
{
	return arflex_ctl_hold(tool_h.ctl) & 0xffu;
}

static uint32_t hold_detail(void)
{
	return (arflex_ctl_hold(tool_h.ctl) >> 8) & 0xffu;
}

static bool reset_latched(void)
{
	return (arflex_ctl_flags(tool_h.ctl) & ARFLEX_FLAG_RESET_REQUIRED) != 0;
}

static int set_command(double v)
{
	return arflex_host_set_param(&tool_h, "command", arflex_f64_bits(v), NULL, T_CALL);
}

/* Waits until the level is @want (and the status READY, unless @any_status). */
static bool reaches(double want, bool ready)
{
	const uint64_t dl = now() + T_WAIT;

	while (next(dl))
		if (fabs(last.command - want) < 1e-12 &&
		    (!ready || last.status == ARFLEX_TOOL_STATE_STATUS_READY))
			return true;
	return false;
}

/* The level stays @want for STILL outputs. */
static bool stays(double want)
{
	const uint64_t dl = now() + T_WAIT;
	int n = 0;

	while (n < STILL && next(dl)) {
		if (last.command != want) {
			fprintf(stderr, "level %.6f, expected to stay %.6f (output %d)\n", last.command,
				want, n);
			return false;
		}
		n++;
	}
	return n == STILL;
}

/* Waits for hold cause @cause (and detail @detail unless negative). */
static bool holds(uint32_t cause, int detail)
{
	const uint64_t dl = now() + T_WAIT;

	while (now() < dl) {
		if (hold_cause() == cause && (detail < 0 || hold_detail() == (uint32_t)detail))
			return true;
		sched_yield();
	}
	fprintf(stderr, "hold word 0x%x, expected cause %u detail %d\n", arflex_ctl_hold(tool_h.ctl),
		cause, detail);
	return false;
}

/* A stop: the spindle runs down to 0, never faster up, each step within max(rate, 2/s) x
 * period; the gripper keeps @level exactly. Then stays there. */
static bool stops_from(double level)
{
	const double max_step = (rate > 2.0 ? rate : 2.0) * (double)PERIOD * 1e-9 + 1e-12;
	const uint64_t dl = now() + T_WAIT;
	double prev = level;
	uint64_t prev_seq = last.seq;

	if (!spindle)
		return stays(level);
	while (next(dl)) {
		if (last.command > prev + 1e-12 ||
		    prev - last.command > max_step * (double)(last.seq - prev_seq)) {
			fprintf(stderr, "spindle level %.6f after %.6f: not a run-down\n", last.command, prev);
			return false;
		}
		prev = last.command;
		prev_seq = last.seq;
		if (last.command == 0)
			return stays(0);
	}
	return false;
}

/* Binds the tool's safety input to the guard and lets it speak NORMAL. */
static int guard_on(void)
{
	atomic_store(&guard_mode, ARFLEX_SAFETY_STATE_MODE_NORMAL);
	atomic_store(&guard_speaks, true);
	return arflex_host_bind(&tool_h, "safety", arflex_host_output_name(&guard_h, "safety"), T_CALL);
}

/* ---- cases ----------------------------------------------------------------------------- */

/* Unbound, or bound to a guard that has not spoken: commands are not taken (the level stays),
 * the hold word names the safety input, no reset is latched (nothing was stopped). A guard
 * that permits: the command is taken (no fresh one needed: it never moved). */
static void case_unguarded(void)
{
	CHECK(set_command(0.8) == 0, "command");
	CHECK(holds(ARFLEX_HOLD_SAFETY_INPUT, ARFLEX_SAFETY_NO_PROVIDER), "unbound");
	CHECK(next(now() + T_WAIT) && stays(0), "moved unguarded");
	CHECK(last.status == ARFLEX_TOOL_STATE_STATUS_BUSY, "status %u while held", last.status);
	CHECK(!reset_latched(), "reset latched without a stop");
	CHECK(arflex_host_bind(&tool_h, "safety", arflex_host_output_name(&guard_h, "safety"),
			       T_CALL) == 0, "bind");
	CHECK(holds(ARFLEX_HOLD_SAFETY_INPUT, ARFLEX_SAFETY_NO_VALUE), "bound, silent");
	CHECK(stays(0), "moved on a silent guard");
	atomic_store(&guard_speaks, true);
	CHECK(reaches(0.8, true), "the permitted command was not taken");
	CHECK(hold_cause() == ARFLEX_HOLD_NONE, "hold word 0x%x", arflex_ctl_hold(tool_h.ctl));
	CHECK(!reset_latched(), "reset latched");
	printf("unguarded: held at 0 without a guard; at 0.8 once the guard permitted\n");
}

/* NORMAL: follows the command. PROTECTIVE_STOP: spindle to 0 / gripper holds, commands
 * refused, no reset latched. Guard NORMAL again (its own reset): waits for a fresh command,
 * the command written during the stop discarded; a command written after it is taken. */
static void case_stop(void)
{
	CHECK(guard_on() == 0, "guard");
	CHECK(set_command(0.8) == 0 && reaches(0.8, true), "NORMAL: command 0.8 not reached");
	CHECK(hold_cause() == ARFLEX_HOLD_NONE, "hold word 0x%x", arflex_ctl_hold(tool_h.ctl));
	atomic_store(&guard_mode, ARFLEX_SAFETY_STATE_MODE_PROTECTIVE_STOP);
	CHECK(holds(ARFLEX_HOLD_SAFETY_INPUT, ARFLEX_SAFETY_STOP), "protective stop");
	CHECK(stops_from(0.8), "the stop");
	CHECK(set_command(0.3) == 0, "command during the stop");
	CHECK(stays(spindle ? 0 : 0.8), "a command was taken during the stop");
	CHECK(!reset_latched(), "a protective stop latched the tool's reset");
	atomic_store(&guard_mode, ARFLEX_SAFETY_STATE_MODE_NORMAL); /* the guard's reset */
	CHECK(holds(ARFLEX_HOLD_AWAIT_COMMAND, 0), "after the guard's reset");
	CHECK(stays(spindle ? 0 : 0.8), "restarted without a fresh command");
	CHECK(set_command(0.5) == 0 && reaches(0.5, true), "the fresh command was not taken");
	CHECK(hold_cause() == ARFLEX_HOLD_NONE, "hold word 0x%x", arflex_ctl_hold(tool_h.ctl));
	printf("stop: %s, waited for the fresh command, then at 0.5\n",
	       spindle ? "ran down to 0" : "kept its grip");
}

/* A guard that permitted and is lost (silent: stale; then unbound): spindle to 0 / gripper
 * holds, the reset is latched and refused while the cause persists; with the guard back the
 * reset is taken, the tool waits for a fresh command (the reset alone does not restart it),
 * and a command after the reset is taken. */
static void case_lost(void)
{
	for (int round = 0; round < 2; round++) {
		const char *how = round == 0 ? "silent" : "unbound";
		const double at = round == 0 ? 0.8 : 0.6;

		if (round == 0)
			CHECK(guard_on() == 0, "guard");
		CHECK(set_command(at) == 0 && reaches(at, true), "%s: command not reached", how);
		if (round == 0)
			atomic_store(&guard_speaks, false);
		else
			CHECK(arflex_host_unbind(&tool_h, "safety", T_CALL) == 0, "unbind");
		CHECK(holds(ARFLEX_HOLD_SAFETY_INPUT, round == 0 ? ARFLEX_SAFETY_STALE
								  : ARFLEX_SAFETY_NO_PROVIDER), "%s", how);
		CHECK(stops_from(at), "%s: the stop", how);
		CHECK(reset_latched(), "%s: the loss did not latch a reset", how);
		CHECK(arflex_host_reset(&tool_h, T_CALL) == -EBUSY, "%s: reset while lost", how);
		CHECK(set_command(0.2) == 0 && stays(spindle ? 0 : at), "%s: command taken", how);
		if (round == 0)
			atomic_store(&guard_speaks, true);
		else
			CHECK(guard_on() == 0, "rebind");
		CHECK(holds(ARFLEX_HOLD_NONE, 0), "%s: the guard back", how);
		CHECK(reset_latched() && stays(spindle ? 0 : at), "%s: left the stop without reset", how);
		CHECK(arflex_host_reset(&tool_h, T_CALL) == 0, "%s: reset", how);
		CHECK(holds(ARFLEX_HOLD_AWAIT_COMMAND, 0), "%s: after the reset", how);
		CHECK(stays(spindle ? 0 : at), "%s: the reset alone restarted it", how);
		CHECK(set_command(at / 2) == 0 && reaches(at / 2, true), "%s: fresh command not taken", how);
		CHECK(hold_cause() == ARFLEX_HOLD_NONE && !reset_latched(), "%s: hold 0x%x", how,
		      arflex_ctl_hold(tool_h.ctl));
		printf("lost (%s): %s, reset refused while lost, then reset + command: at %.2f\n", how,
		       spindle ? "ran down to 0" : "kept its grip", at / 2);
	}
}

/* The command input bound: after a stop, the same value written again is no fresh command,
 * another value is; the parameter is not the source then. */
static void case_command_input(void)
{
	static struct arflex_host script;
	struct arflex_host_output o = { "command",
					{ ARFLEX_PORT_STATE, sample_t, 1, ARFLEX_OVERFLOW_NONE } };
	struct arflex_host_opts opts;
	struct arflex_sample s;
	int r;

	memset(&opts, 0, sizeof(opts));
	opts.runtime = rid;
	opts.instance = "script";
	opts.config.period_ns = MS;
	opts.outputs = &o;
	opts.noutputs = 1;
	CHECK((r = arflex_host_create(&script, &opts)) == 0, "script: %d", r);
	memset(&s, 0, sizeof(s));
	s.seq = 1;
	s.value = 0.6;
	arflex_state_write(arflex_host_output(&script, "command"), &s, sizeof(s));
	CHECK(arflex_host_bind(&tool_h, "command", arflex_host_output_name(&script, "command"),
			       T_CALL) == 0, "bind command");
	CHECK(guard_on() == 0, "guard");
	CHECK(reaches(0.6, true), "input command 0.6 not reached");
	atomic_store(&guard_mode, ARFLEX_SAFETY_STATE_MODE_PROTECTIVE_STOP);
	CHECK(holds(ARFLEX_HOLD_SAFETY_INPUT, ARFLEX_SAFETY_STOP), "stop");
	CHECK(stops_from(0.6), "the stop");
	atomic_store(&guard_mode, ARFLEX_SAFETY_STATE_MODE_NORMAL);
	CHECK(holds(ARFLEX_HOLD_AWAIT_COMMAND, 0), "after the guard's reset");
	s.seq++; /* the same value again: not a command */
	arflex_state_write(arflex_host_output(&script, "command"), &s, sizeof(s));
	CHECK(set_command(0.1) == 0, "parameter"); /* not the source while the input is bound */
	CHECK(stays(spindle ? 0 : 0.6), "restarted on a repeated value or the parameter");
	CHECK(hold_cause() == ARFLEX_HOLD_AWAIT_COMMAND, "hold 0x%x", arflex_ctl_hold(tool_h.ctl));
	s.seq++;
	s.value = 0.3;
	arflex_state_write(arflex_host_output(&script, "command"), &s, sizeof(s));
	CHECK(reaches(0.3, true), "a new input value after the reset was not taken");
	CHECK(arflex_host_unbind(&tool_h, "command", T_CALL) == 0, "unbind command");
	arflex_host_destroy(&script);
	printf("command input: repeated value ignored after the stop, a new one taken\n");
}

int main(int argc, char **argv)
{
	int r;

	if (argc != 5 || (strcmp(argv[2], "gripper") != 0 && strcmp(argv[2], "spindle") != 0)) {
		fprintf(stderr, "usage: %s <unguarded|stop|lost|command_input> <gripper|spindle> <exe> "
			"<contract>\n", argv[0]);
		return 2;
	}
	spindle = strcmp(argv[2], "spindle") == 0;
	exe = argv[3];
	contract_xml = argv[4];
	th_rid(rid, sizeof(rid), "tool");
	th_track(rid, "gripper");
	th_track(rid, "spindle");
	th_track(rid, "guard");
	th_track(rid, "script");
	r = guard_create();
	if (r == 0)
		r = tool_create();
	if (r < 0) {
		fprintf(stderr, "FAIL: setup: %s\n", strerror(-r));
		failures++;
	} else if (strcmp(argv[1], "unguarded") == 0) {
		case_unguarded();
	} else if (strcmp(argv[1], "stop") == 0) {
		case_stop();
	} else if (strcmp(argv[1], "lost") == 0) {
		case_lost();
	} else if (strcmp(argv[1], "command_input") == 0) {
		case_command_input();
	} else {
		fprintf(stderr, "unknown case '%s'\n", argv[1]);
		failures++;
	}
	if (failures)
		fprintf(stderr, "last output: level %.6f status %u seq %llu; hold 0x%x flags 0x%x\n",
			last.command, last.status, (unsigned long long)last.seq,
			tool_h.ctl ? arflex_ctl_hold(tool_h.ctl) : 0,
			tool_h.ctl ? arflex_ctl_flags(tool_h.ctl) : 0);
	tool_destroy();
	guard_destroy();
	if (th_leftovers(rid) != 0 || !th_no_children())
		failures++;
	if (failures)
		return 1;
	printf("ok %s %s\n", argv[1], argv[2]);
	return 0;
}
