/*
 * tool.c - RT half of the interchangeable tool components tool-gripper and tool-spindle
 * (README.md). Both provide the same output port `tool` (arflex.ToolState) and read the same
 * optional input `command` (arflex.Sample: the requested actuation level 0..1; while it is
 * unbound the mutable parameter `command` is used). The level follows the command at the
 * tool's rate (parameter `rate`, 1/s); status BUSY while moving, READY when there.
 *
 * Built twice from this file: TOOL_KIND_GRIPPER (opening 0 closed .. 1 open, tool id 1,
 * 25 kg) and TOOL_KIND_SPINDLE (speed fraction, tool id 2, 30 kg, longer TCP).
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "arflex/component.h"
#include "arflex_types/sample.h"
#include "arflex_types/tool_state.h"

#if defined(TOOL_KIND_GRIPPER)
#define TOOL_NAME "tool-gripper"
#define TOOL_ID 1u
#define TOOL_MASS 25.0
#define TOOL_TCP_X 0.30
#define TOOL_COM_X 0.12
#elif defined(TOOL_KIND_SPINDLE)
#define TOOL_NAME "tool-spindle"
#define TOOL_ID 2u
#define TOOL_MASS 30.0
#define TOOL_TCP_X 0.35
#define TOOL_COM_X 0.15
#else
#error "define TOOL_KIND_GRIPPER or TOOL_KIND_SPINDLE"
#endif

static struct arflex_port *out;
static struct arflex_input *in_cmd;
static int p_command, p_rate;
static double level, cmd;
static uint64_t seq;

static int configure(struct arflex_component *c, void *user)
{
	static const struct arflex_port_type tool_t = { ARFLEX_TYPE_TOOL_STATE_NAME, 1, 0,
							 sizeof(struct arflex_tool_state) };
	static const struct arflex_port_type sample_t = { ARFLEX_TYPE_SAMPLE_NAME, 1, 0,
							   sizeof(struct arflex_sample) };
	int r;

	(void)user;
	r = arflex_component_output(c, "tool", ARFLEX_PORT_STATE, &tool_t, &out);
	if (r < 0) {
		fprintf(stderr, TOOL_NAME ": output tool: %s\n", strerror(-r));
		return r;
	}
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
	return 0;
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

static int update(struct arflex_component *c, void *user, uint64_t release_ns)
{
	struct arflex_sample in;
	double step;

	(void)user;
	if (arflex_input_bound(in_cmd)) {
		if (arflex_input_state_read(in_cmd, &in, sizeof(in), NULL) == 1 && isfinite(in.value))
			cmd = in.value;
	} else {
		cmd = arflex_param_f64(c, p_command);
	}
	cmd = cmd < 0 ? 0 : cmd > 1 ? 1 : cmd;
	step = arflex_param_f64(c, p_rate) * (double)arflex_component_ctl(c)->config.period_ns * 1e-9;
	if (fabs(cmd - level) <= step)
		level = cmd;
	else
		level += cmd > level ? step : -step;
	return write_state(release_ns, level == cmd ? ARFLEX_TOOL_STATE_STATUS_READY
						    : ARFLEX_TOOL_STATE_STATUS_BUSY);
}

/* Safe mode: a gripper keeps its grip (hold), a spindle runs down (zero). */
static int safe(struct arflex_component *c, void *user, enum arflex_safe_mode mode, bool first)
{
	(void)c;
	(void)user;
	(void)first;
#if defined(TOOL_KIND_SPINDLE)
	(void)mode;
	level = 0;
#else
	if (mode == ARFLEX_SAFE_ZERO)
		level = 0;
#endif
	return write_state(arflex_sys_now_ns(), ARFLEX_TOOL_STATE_STATUS_BUSY);
}

static const struct arflex_component_ops ops = {
	.name = TOOL_NAME, .configure = configure, .update = update, .safe = safe,
};

int main(int argc, char **argv)
{
	return arflex_component_main(argc, argv, &ops);
}
