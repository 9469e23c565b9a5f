/* The safety-input gate of components that move hardware (see arflex/safety_gate.h). */
#include "arflex/safety_gate.h"

#include <errno.h>
#include <string.h>

void arflex_safety_gate_init(struct arflex_safety_gate *g, struct arflex_input *in,
			     uint64_t max_age_ns)
{
	memset(g, 0, sizeof(*g));
	g->in = in;
	g->max_age_ns = max_age_ns;
	g->verdict = ARFLEX_SAFETY_NO_PROVIDER;
}

/* A known mode, and the bounds arflex.SafetyState declares (finite fields, power scale in
 * [0, 1], forces >= 0: the generated arflex_safety_state_valid). */
static bool state_ok(const struct arflex_safety_state *s)
{
	return s->mode <= ARFLEX_SAFETY_STATE_MODE_PROTECTIVE_STOP && arflex_safety_state_valid(s);
}

bool arflex_safety_permits(enum arflex_safety_verdict v)
{
	return v == ARFLEX_SAFETY_NORMAL || v == ARFLEX_SAFETY_LIMITED;
}

double arflex_safety_gate_scale(const struct arflex_safety_gate *g)
{
	if (g->verdict == ARFLEX_SAFETY_NORMAL)
		return 1.0;
	if (g->verdict == ARFLEX_SAFETY_LIMITED)
		return g->state.power_scale;
	return 0.0;
}

static enum arflex_safety_verdict judge(struct arflex_safety_gate *g, struct arflex_port *p,
				       uint32_t binding, uint64_t now_ns)
{
	struct arflex_safety_state s;
	int r;

	if (binding != g->binding) { /* another provider, or the same restarted: must speak */
		g->binding = binding;
		g->seen = false;
		g->bad = false;
	}
	if (binding == 0 || !p)
		return ARFLEX_SAFETY_NO_PROVIDER;
	r = arflex_state_read(p, &s, sizeof(s), NULL);
	if (r == 1) {
		g->bad = !state_ok(&s);
		if (g->bad) {
			g->rejected++;
			if (g->in) /* counted on the input too: the DRCR names its provider */
				arflex_input_reject(g->in);
			g->seen = false; /* the last valid value is not the provider's word now */
		} else {
			g->state = s;
			g->seen = true;
		}
	}
	r = arflex_port_age(p, now_ns, &g->age_ns);
	if (r == -EPROTO)
		return ARFLEX_SAFETY_DAMAGED;
	if (g->bad)
		return ARFLEX_SAFETY_INVALID;
	if (!g->seen || r == -ENODATA)
		return ARFLEX_SAFETY_NO_VALUE;
	if (r < 0)
		return ARFLEX_SAFETY_DAMAGED;
	if (g->age_ns <= g->max_age_ns) {
		g->late_since_ns = 0;
	} else {
		if (!g->late_since_ns)
			g->late_since_ns = now_ns ? now_ns : 1;
		if (now_ns - g->late_since_ns >= g->max_age_ns / 2)
			return ARFLEX_SAFETY_STALE;
	}
	if (g->state.mode == ARFLEX_SAFETY_STATE_MODE_PROTECTIVE_STOP)
		return ARFLEX_SAFETY_STOP;
	if (g->state.mode == ARFLEX_SAFETY_STATE_MODE_LIMITED)
		return ARFLEX_SAFETY_LIMITED;
	return ARFLEX_SAFETY_NORMAL;
}

enum arflex_safety_verdict arflex_safety_gate_judge(struct arflex_safety_gate *g,
						    struct arflex_port *p, uint32_t binding,
						    uint64_t now_ns)
{
	g->verdict = judge(g, p, binding, now_ns);
	return g->verdict;
}

enum arflex_safety_verdict arflex_safety_gate_check(struct arflex_safety_gate *g,
						    uint64_t now_ns)
{
	return arflex_safety_gate_judge(g, arflex_input_port(g->in), arflex_input_binding(g->in),
					now_ns);
}

const char *arflex_safety_verdict_name(enum arflex_safety_verdict v)
{
	switch (v) {
	case ARFLEX_SAFETY_NORMAL:
		return "normal";
	case ARFLEX_SAFETY_LIMITED:
		return "limited";
	case ARFLEX_SAFETY_STOP:
		return "protective stop";
	case ARFLEX_SAFETY_NO_PROVIDER:
		return "no provider";
	case ARFLEX_SAFETY_NO_VALUE:
		return "no value";
	case ARFLEX_SAFETY_STALE:
		return "stale";
	case ARFLEX_SAFETY_INVALID:
		return "invalid value";
	case ARFLEX_SAFETY_DAMAGED:
		return "segment damaged";
	}
	return "?";
}
