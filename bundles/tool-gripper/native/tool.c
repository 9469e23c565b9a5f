/*
 * tool.c - RT half of the interchangeable tool components tool-gripper and tool-spindle
 * (README.md). Both provide the same output port `tool` (arflex.ToolState) and read the same
 * optional input `command` (arflex.Sample: the requested actuation level 0..1; while it is
 * unbound the mutable parameter `command` is used). The level follows the command at the
 * tool's rate (parameter `rate`, 1/s); status BUSY while moving or held, READY when there.
 *
 * Safety input `safety` (arflex.SafetyState, role=safety: the force guard) permits actuation
 * (docs/safety.md, D11), judged every cycle by rt-core/safety (arflex_safety_gate): while it
 * is unbound, has not spoken, is older than safety_max_age_ms, invalid, damaged or in a
 * protective stop, the spindle runs down to 0 (at its rate, at least STOP_RATE) and the
 * gripper keeps its grip (it never opens by itself: dropping a part is not safe); commands
 * are refused. A guard that had permitted actuation and is lost (not merely stopping) latches
 * an operator reset. After any stop (protective stop, lost guard, safe mode, a restart) the
 * tool holds until the reset AND a fresh command: a write of parameter `command` (command
 * input unbound) or a new value on the command input different from the one it held during
 * the stop, taken after the causes are gone. Before a guard first permitted (nothing was
 * stopped) the tool holds without that. LIMITED: the level moves at rate x power_scale, and
 * the spindle's speed is capped at power_scale.
 *
 * Threads: configure on the main thread; start/update/safe on the RT thread: no allocation,
 * blocking or printing there.
 *
 * Built twice from this file: TOOL_KIND_GRIPPER (opening 0 closed .. 1 open, tool id 1,
 * 25 kg) and TOOL_KIND_SPINDLE (speed fraction, tool id 2, 30 kg, longer TCP).
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "arflex/component.h"
#include "arflex/safety_gate.h"
#include "arflex_types/safety_state.h"
#include "arflex_types/sample.h"
#include "arflex_types/tool_state.h"

#if defined(TOOL_KIND_GRIPPER)
#define TOOL_NAME "tool-gripper"
#define TOOL_ID 1u
#define TOOL_MASS 25.0
#define TOOL_TCP_X 0.30
#define TOOL_COM_X 0.12
#define TOOL_SPINDLE 0
#elif defined(TOOL_KIND_SPINDLE)
#define TOOL_NAME "tool-spindle"
#define TOOL_ID 2u
#define TOOL_MASS 30.0
#define TOOL_TCP_X 0.35
#define TOOL_COM_X 0.15
#define TOOL_SPINDLE 1
#else
#error "define TOOL_KIND_GRIPPER or TOOL_KIND_SPINDLE"
#endif

/* A safety value older than this (seen so for half as long in the tool's own cycles) is stale
 * (the parameter safety_max_age_ms overrides it). */
#define SAFETY_MAX_AGE_NS 20000000ull /* 20 ms */
/* A stopping spindle decelerates at its rate, but never slower than this (1/s): from full
 * speed to 0 within 0.5 s whatever `rate` was set to. */
#define STOP_RATE 2.0

static struct arflex_port *out;
static struct arflex_input *in_cmd, *in_safety;
static int p_command, p_rate, p_safety_max_age = -1;
static double level, cmd;
static uint64_t seq;

static struct arflex_safety_gate gate;
static bool permitted;    /* the safety input permitted actuation since start */
static bool loss_latched; /* the reset for this loss of the guard is latched */
/* Reset permits, it does not start (SAFETY.md 2): after a stop the tool holds until a fresh
 * command taken after the stop's causes are gone. */
static bool await_command;
/* The command source as last seen while a stop held (the "mark"): writes of parameter
 * `command`, and the command input's value on its binding. */
static uint64_t mark_writes;
static double mark_value;
static uint32_t mark_binding; /* 0: no input value marked */
static uint32_t cmd_binding;  /* command input binding `cmd` was last read on (0: parameter) */

static int configure(struct arflex_component *c, void *user)
{
	static const struct arflex_port_type tool_t = { ARFLEX_TYPE_TOOL_STATE_NAME, 1, 0,
							 sizeof(struct arflex_tool_state) };
	static const struct arflex_port_type sample_t = { ARFLEX_TYPE_SAMPLE_NAME, 1, 0,
							   sizeof(struct arflex_sample) };
	static const struct arflex_port_type safety_t = { ARFLEX_TYPE_SAFETY_STATE_NAME, 1, 0,
							   sizeof(struct arflex_safety_state) };
	int r;

	(void)user;
	r = arflex_component_output(c, "tool", ARFLEX_PORT_STATE, &tool_t, &out);
	if (r < 0) {
		fprintf(stderr, TOOL_NAME ": output tool: %s\n", strerror(-r));
		return r;
	}
	r = arflex_component_input(c, "safety", ARFLEX_PORT_STATE, &safety_t, &in_safety);
	if (r < 0)
		return r;
	r = arflex_component_input(c, "command", ARFLEX_PORT_STATE, &sample_t, &in_cmd);
	if (r < 0)
		return r;
	p_command = arflex_component_param(c, "command");
	p_rate = arflex_component_param(c, "rate");
	if (p_command < 0 || p_rate < 0) {
		fprintf(stderr, TOOL_NAME ": parameter '%s' missing from the control block\n",
			p_command < 0 ? "command" : "rate");
		return -ENOENT;
	}
	p_safety_max_age = arflex_component_param(c, "safety_max_age_ms"); /* optional */
	return 0;
}

static uint64_t safety_max_age_ns(struct arflex_component *c)
{
	return p_safety_max_age >= 0
		       ? (uint64_t)(arflex_param_f64(c, p_safety_max_age) * 1e6)
		       : SAFETY_MAX_AGE_NS;
}

static double period_s(struct arflex_component *c)
{
	return (double)arflex_component_ctl(c)->config.period_ns * 1e-9;
}

/* The current command source into `cmd` (clamped to 0..1): the input's newest finite value
 * while it is bound (the last one until a new one arrives), else the parameter. */
static void read_command(struct arflex_component *c)
{
	struct arflex_sample in;

	if (arflex_input_bound(in_cmd)) {
		if (arflex_input_state_read(in_cmd, &in, sizeof(in), NULL) == 1 &&
		    isfinite(in.value)) {
			cmd = in.value < 0 ? 0 : in.value > 1 ? 1 : in.value;
			cmd_binding = arflex_input_binding(in_cmd);
		}
	} else {
		cmd = arflex_param_f64(c, p_command);
		cmd = cmd < 0 ? 0 : cmd > 1 ? 1 : cmd;
		cmd_binding = 0;
	}
}

/* The command source as it is now is not a command: only what changes after counts. */
static void mark_command(struct arflex_component *c)
{
	mark_writes = arflex_param_writes(c, p_command);
	mark_value = cmd;
	mark_binding = cmd_binding;
}

/* A fresh command since the mark, on the source in use: a write of the parameter (also of the
 * same value) while the input is unbound; a value of the input, on the binding marked, that
 * differs from the marked one. The first value of another binding becomes the mark. */
static bool fresh_command(struct arflex_component *c)
{
	if (!arflex_input_bound(in_cmd)) {
		mark_binding = 0;
		return arflex_param_writes(c, p_command) != mark_writes;
	}
	mark_writes = arflex_param_writes(c, p_command); /* not the source: not a command */
	if (cmd_binding != arflex_input_binding(in_cmd))
		return false; /* nothing read on this binding yet */
	if (mark_binding != cmd_binding) {
		mark_binding = cmd_binding;
		mark_value = cmd;
		return false;
	}
	return cmd != mark_value;
}

/* Judges the safety input (update and safe mode): permits, or a stop. A guard that had
 * permitted and is gone (not merely stopping) latches the operator reset; any stop after the
 * first permission needs the fresh command afterwards. */
static enum arflex_safety_verdict judge(struct arflex_component *c)
{
	enum arflex_safety_verdict v;

	gate.max_age_ns = safety_max_age_ns(c);
	v = arflex_safety_gate_check(&gate, arflex_sys_now_ns());
	if (arflex_safety_permits(v)) {
		permitted = true;
		loss_latched = false;
		return v;
	}
	if (permitted) {
		await_command = true;
		if (v != ARFLEX_SAFETY_STOP && !loss_latched) {
			arflex_component_require_reset(c);
			loss_latched = true;
		}
	}
	return v;
}

/* Moves the level towards @target by at most @step. */
static void ramp(double target, double step)
{
	if (fabs(target - level) <= step)
		level = target;
	else
		level += target > level ? step : -step;
}

/* The stop: the spindle runs down, the gripper keeps its grip. */
static void stop_step(struct arflex_component *c)
{
#if TOOL_SPINDLE
	double rate = arflex_param_f64(c, p_rate);

	ramp(0, (rate > STOP_RATE ? rate : STOP_RATE) * period_s(c));
#else
	(void)c;
#endif
}

static int write_state(uint64_t t_ns, uint32_t status)
{
	struct arflex_tool_state s;

	memset(&s, 0, sizeof(s));
	s.t_ns = (int64_t)t_ns;
	s.seq = ++seq;
	s.tool_id = TOOL_ID;
	s.status = status;
	s.tcp_p[0] = TOOL_TCP_X;
	s.tcp_quat[0] = 1.0;
	s.mass = TOOL_MASS;
	s.com[0] = TOOL_COM_X;
	s.command = level;
	return arflex_state_write(out, &s, sizeof(s));
}

static int start(struct arflex_component *c, void *user)
{
	const struct arflex_ctl *ctl = arflex_component_ctl(c);

	(void)user;
	permitted = false;
	loss_latched = false;
	arflex_safety_gate_init(&gate, in_safety, safety_max_age_ns(c));
	/* A restart of a component that moves hardware comes with a reset to take (the runtime
	 * sets RESET_REQUIRED before the spawn): after it, wait for a fresh command too. */
	await_command = (arflex_ctl_flags(ctl) & ARFLEX_FLAG_RESET_REQUIRED) != 0;
	read_command(c);
	mark_command(c);
	return 0;
}

static int update(struct arflex_component *c, void *user, uint64_t release_ns)
{
	enum arflex_safety_verdict v;
	bool permits;
	double step, target;

	(void)user;
	v = judge(c);
	permits = arflex_safety_permits(v);
	read_command(c);
	if (await_command) {
		if (!permits)
			mark_command(c); /* commands while the cause holds are discarded */
		else if (fresh_command(c))
			await_command = false; /* the fresh command after the reset */
	}
	if (!permits)
		arflex_component_hold(c, ARFLEX_HOLD_SAFETY_INPUT, v,
				      arflex_input_index(c, in_safety));
	else if (await_command)
		arflex_component_hold(c, ARFLEX_HOLD_AWAIT_COMMAND, 0, 0);
	else
		arflex_component_hold(c, ARFLEX_HOLD_NONE, 0, 0);

	if (!permits || await_command) {
		stop_step(c);
		return write_state(release_ns, ARFLEX_TOOL_STATE_STATUS_BUSY);
	}
	step = arflex_param_f64(c, p_rate) * period_s(c);
	target = cmd;
	if (v == ARFLEX_SAFETY_LIMITED) {
		const double scale = arflex_safety_gate_scale(&gate);
#if TOOL_SPINDLE
		if (target > scale)
			target = scale;
		if (target > level)
			step *= scale; /* spins up at reduced power; slows down at its rate */
#else
		step *= scale;
#endif
	}
	ramp(target, step);
	return write_state(release_ns, level == cmd ? ARFLEX_TOOL_STATE_STATUS_READY
						    : ARFLEX_TOOL_STATE_STATUS_BUSY);
}

/* Safe mode (runtime heartbeat lost, a latched reset): a spindle runs down, a gripper keeps
 * its grip (hold) or closes to 0 with safe="zero". The safety input is judged on, so the hold
 * word names it while it does not permit (rt-core refuses the RESET then). */
static int safe(struct arflex_component *c, void *user, enum arflex_safe_mode mode, bool first)
{
	enum arflex_safety_verdict v;

	(void)user;
	(void)first;
	v = judge(c);
	await_command = true; /* a stop: after the reset, a fresh command */
	read_command(c);
	mark_command(c);
	if (!arflex_safety_permits(v))
		arflex_component_hold(c, ARFLEX_HOLD_SAFETY_INPUT, v,
				      arflex_input_index(c, in_safety));
	else
		arflex_component_hold(c, ARFLEX_HOLD_NONE, 0, 0);
#if TOOL_SPINDLE
	(void)mode;
#else
	if (mode == ARFLEX_SAFE_ZERO)
		level = 0;
#endif
	stop_step(c);
	return write_state(arflex_sys_now_ns(), ARFLEX_TOOL_STATE_STATUS_BUSY);
}

static const struct arflex_component_ops ops = {
	.name = TOOL_NAME, .configure = configure, .start = start, .update = update, .safe = safe,
};

int main(int argc, char **argv)
{
	return arflex_component_main(argc, argv, &ops);
}
