/* The contract reader's <ports> (SPEC 6): an <out> becomes an output port the host creates, an
 * <in> an input the harness binds (with its type from the caller's table), at most one <bind>
 * per input. */
#include <inttypes.h>
#include <stdio.h>
#include <string.h>

#include "internal.h"

static bool port_declared(const struct arflex_host_contract *c, const char *name)
{
	for (unsigned i = 0; i < c->noutputs; i++)
		if (!strcmp(c->output_ports[i], name))
			return true;
	for (unsigned i = 0; i < c->ninputs; i++)
		if (!strcmp(c->inputs[i].port, name))
			return true;
	return false;
}

/* What an <in> and an <out> share: name, type, typeVersion, method (SPEC 6.1-6.3, 6.7). */
static bool port_common(struct loader *L, const XML_Char **atts, const char *dir,
			const char **name_out, const struct arflex_host_type **type_out,
			enum arflex_port_method *method_out)
{
	char where[64], field[96];
	const char *name = arflex_hc_required(L, atts, "6.1", dir, "name");
	const char *type = name ? arflex_hc_required(L, atts, "6.2", dir, "type") : NULL;
	const char *tv = type ? arflex_hc_required(L, atts, "6.2", dir, "typeVersion") : NULL;
	const char *method = tv ? arflex_hc_required(L, atts, "6.3", dir, "method") : NULL;
	const struct arflex_host_type *t = NULL;
	unsigned major, minor, bit;

	if (!method)
		return false;
	snprintf(where, sizeof(where), "ports/%s[%.32s]", dir, name);
	if (!arflex_hc_port_name_ok(name)) {
		arflex_hc_fail(L, "6.1", where, "port name '%s' is not [a-z][a-z0-9_]{0,31}",
			       name);
		return false;
	}
	if (port_declared(L->c, name)) {
		arflex_hc_fail(L, "6.1", where, "duplicate port '%s' (inputs and outputs share "
			       "one name space)", name);
		return false;
	}
	snprintf(field, sizeof(field), "%s/@type", where);
	if (!strncmp(type, "eval.", 5)) {
		arflex_hc_fail(L, "6.7", field,
			       "%s is an evaluation-only type, not bindable by components", type);
		return false;
	}
	for (unsigned i = 0; i < L->ntypes && !t; i++)
		if (L->types[i].name && !strcmp(L->types[i].name, type))
			t = &L->types[i];
	if (!t) {
		char known[256] = "";
		size_t len = 0;

		for (unsigned i = 0; i < L->ntypes && len < sizeof(known); i++)
			len += (size_t)snprintf(known + len, sizeof(known) - len, "%s%s",
						i ? ", " : "", L->types[i].name);
		arflex_hc_fail(L, "6.2", field,
			       "unknown port type '%s' (known to this harness: %s)", type,
			       L->ntypes ? known : "none");
		return false;
	}
	snprintf(field, sizeof(field), "%s/@typeVersion", where);
	if (!arflex_hc_parse_type_version(tv, &major, &minor)) {
		arflex_hc_fail(L, "6.2", field, "bad type version '%s' (MAJOR.MINOR)", tv);
		return false;
	}
	if (t->major != major || t->minor < minor) {
		arflex_hc_fail(L, "6.2", field, "%s %u.%u is not compatible with the harness's "
			       "definition %u.%u (same major, minor at least the contract's)", type,
			       major, minor, t->major, t->minor);
		return false;
	}
	snprintf(field, sizeof(field), "%s/@method", where);
	if (!strcmp(method, "state"))
		*method_out = ARFLEX_PORT_STATE;
	else if (!strcmp(method, "stream"))
		*method_out = ARFLEX_PORT_STREAM;
	else if (!strcmp(method, "frame"))
		*method_out = ARFLEX_PORT_FRAME;
	else {
		arflex_hc_fail(L, "6.3", field, "unknown method '%s' (state, stream or frame)",
			       method);
		return false;
	}
	bit = 1u << (*method_out - 1);
	if (!(t->methods & bit)) {
		arflex_hc_fail(L, "6.3", field, "%s does not allow method %s (methods bits %#x: "
			       "1 state, 2 stream, 4 frame)", type, method, t->methods);
		return false;
	}
	*name_out = name;
	*type_out = t;
	return true;
}

void arflex_hc_on_out(struct loader *L, const XML_Char **atts)
{
	struct arflex_host_contract *c = L->c;
	const struct arflex_host_type *t;
	enum arflex_port_method method;
	const char *name, *depth, *overflow;
	struct arflex_port_spec *spec;
	char field[96];
	int64_t d = 1;

	if (!port_common(L, atts, "out", &name, &t, &method))
		return;
	if (c->noutputs >= ARFLEX_MAX_OUTPUTS) {
		arflex_hc_fail(L, "6", "ports/out", "more than %u outputs (what rt-core holds)",
			       ARFLEX_MAX_OUTPUTS);
		return;
	}
	depth = arflex_hc_attr(atts, "depth");
	overflow = arflex_hc_attr(atts, "overflow");
	snprintf(field, sizeof(field), "ports/out[%s]/@depth", name);
	if (depth && !arflex_hc_parse_int(depth, &d)) {
		arflex_hc_fail(L, "6.4", field, "bad number '%s' (an integer)", depth);
		return;
	}
	if (method == ARFLEX_PORT_STATE && d != 1) {
		arflex_hc_fail(L, "6.4", field, "a state output has depth 1, not %" PRId64, d);
		return;
	}
	if (method != ARFLEX_PORT_STATE && !depth) {
		arflex_hc_fail(L, "6.4", field, "required for a %s output",
			       method == ARFLEX_PORT_STREAM ? "stream" : "frame");
		return;
	}
	if (d < 1 || d > (method == ARFLEX_PORT_FRAME ? 256 : 65536)) {
		arflex_hc_fail(L, "6.4", field, "depth %" PRId64 " not in 1..%d", d,
			       method == ARFLEX_PORT_FRAME ? 256 : 65536);
		return;
	}
	snprintf(field, sizeof(field), "ports/out[%s]/@overflow", name);
	if (overflow && method != ARFLEX_PORT_STREAM) {
		arflex_hc_fail(L, "6.4", field, "only on stream outputs");
		return;
	}
	if (overflow && strcmp(overflow, "drop-oldest") && strcmp(overflow, "drop-newest")) {
		arflex_hc_fail(L, "6.4", field,
			       "unknown overflow '%s' (drop-oldest or drop-newest)", overflow);
		return;
	}
	if ((uint64_t)t->size + t->max_payload > ARFLEX_PORT_MAX_ELEM) {
		arflex_hc_fail(L, "6.2", field, "%s: element of %" PRIu64 " bytes is too large",
			       t->name, (uint64_t)t->size + t->max_payload);
		return;
	}
	snprintf(c->output_ports[c->noutputs], ARFLEX_NAME_SIZE, "%s", name);
	spec = &c->outputs[c->noutputs].spec;
	spec->method = method;
	spec->type.name = t->name;
	spec->type.major = t->major;
	spec->type.minor = t->minor;
	spec->type.elem_size = t->size + t->max_payload; /* as the DRCR's Segments */
	spec->depth = (uint32_t)d;
	spec->overflow = method != ARFLEX_PORT_STREAM ? ARFLEX_OVERFLOW_NONE
			 : overflow && !strcmp(overflow, "drop-newest") ? ARFLEX_OVERFLOW_DROP_NEWEST
			 : ARFLEX_OVERFLOW_DROP_OLDEST;
	c->noutputs++;
}

void arflex_hc_on_in(struct loader *L, const XML_Char **atts)
{
	struct arflex_host_contract *c = L->c;
	struct arflex_host_input *in;
	const struct arflex_host_type *t;
	enum arflex_port_method method;
	const char *name;
	bool optional = false, safety = false;
	char where[64];

	L->bind_seen = false;
	if (!port_common(L, atts, "in", &name, &t, &method))
		return;
	snprintf(where, sizeof(where), "ports/in[%s]", name);
	if (!arflex_hc_opt_bool(L, atts, "6.5", where, "optional", &optional) ||
	    !arflex_hc_opt_bool(L, atts, "6.8", where, "safety", &safety))
		return;
	if (c->ninputs >= ARFLEX_MAX_INPUTS) {
		arflex_hc_fail(L, "6", "ports/in", "more than %u inputs (what rt-core holds)",
			       ARFLEX_MAX_INPUTS);
		return;
	}
	if (safety && strcmp(t->name, "arflex.SafetyState")) {
		arflex_hc_fail(L, "6.8", where,
			       "a safety input carries arflex.SafetyState, not %s", t->name);
		return;
	}
	if (safety && arflex_hc_attr(atts, "optional") && !optional) {
		arflex_hc_fail(L, "6.8", where,
			       "a safety input is optional; optional=\"false\" refused");
		return;
	}
	in = &c->inputs[c->ninputs++];
	snprintf(in->port, sizeof(in->port), "%s", name);
	in->type = t;
	in->method = method;
	in->optional = optional || safety;
	in->safety = safety;
	L->has_safety_input |= safety;
}

void arflex_hc_on_bind(struct loader *L, const XML_Char **atts)
{
	const char *filter = arflex_hc_attr(atts, "filter");
	const char *component = arflex_hc_attr(atts, "component");
	const char *port = arflex_hc_attr(atts, "port");

	if (L->bind_seen) {
		arflex_hc_fail(L, "6.5", "ports/in/bind", "at most one <bind> per input");
		return;
	}
	L->bind_seen = true;
	if (filter && (component || port))
		arflex_hc_fail(L, "6.5", "ports/in/bind", "either component and port, or a filter");
	else if (!filter && (!component || !port))
		arflex_hc_fail(L, "6.5", "ports/in/bind", "component and port come together");
}
