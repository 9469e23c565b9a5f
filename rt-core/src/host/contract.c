/* The C host API reads a component contract (contracts/SPEC.md) with expat. See
 * arflex/host_contract.h for what is read and how it maps. */
#include "arflex/host_contract.h"

#include <errno.h>
#include <expat.h>
#include <fcntl.h>
#include <float.h>
#include <inttypes.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#define CONTRACT_NS "urn:arflex:contract:1"
#define NS_SEP '|'
#define MAX_FILE (1u << 20)     /* SPEC 2.1 */
#define MAX_DEPTH 16
#define MAX_ELEMENTS 10000
#define MAX_ATTRS 32
#define MAX_ATTR_LEN 4096
#define MS UINT64_C(1000000)
#define SEC UINT64_C(1000000000)

enum kind {
	K_COMPONENT, K_DESCRIPTION, K_IMPLEMENTATION, K_ATTRIBUTES, K_ATTRIBUTE, K_PORTS, K_IN,
	K_OUT, K_BIND, K_PROPERTIES, K_PROPERTY, K_TIMING, K_RESOURCES, K_CRITICALITY, K_FAULT,
	K_UPDATE, K_STATE, K_CONVERTS_FROM, K_COUNT
};

/* Every element of the format: its name, its parent, its attributes, whether text is
 * allowed in it, and the section of SPEC.md that defines it. */
static const struct elem {
	const char *name;
	int parent;             /* -1: the root */
	const char *const *attrs;
	bool text;
	const char *sec;
} ELEMS[K_COUNT] = {
	[K_COMPONENT] = { "component", -1, (const char *const[]){ "name", "version", NULL },
			  false, "3" },
	[K_DESCRIPTION] = { "description", K_COMPONENT, (const char *const[]){ NULL }, true,
			    "3.3" },
	[K_IMPLEMENTATION] = { "implementation", K_COMPONENT,
			       (const char *const[]){ "executable", "task", "movesHardware",
						      "motionThrough", NULL }, false, "4" },
	[K_ATTRIBUTES] = { "attributes", K_COMPONENT, (const char *const[]){ NULL }, false, "5" },
	[K_ATTRIBUTE] = { "attribute", K_ATTRIBUTES, (const char *const[]){ "name", "value", NULL },
			  false, "5" },
	[K_PORTS] = { "ports", K_COMPONENT, (const char *const[]){ NULL }, false, "6" },
	[K_IN] = { "in", K_PORTS,
		   (const char *const[]){ "name", "type", "typeVersion", "method", "optional",
					  "safety", NULL }, false, "6" },
	[K_OUT] = { "out", K_PORTS,
		    (const char *const[]){ "name", "type", "typeVersion", "method", "depth",
					   "overflow", NULL }, false, "6" },
	[K_BIND] = { "bind", K_IN, (const char *const[]){ "component", "port", "filter", NULL },
		     false, "6.5" },
	[K_PROPERTIES] = { "properties", K_COMPONENT, (const char *const[]){ NULL }, false, "7" },
	[K_PROPERTY] = { "property", K_PROPERTIES,
			 (const char *const[]){ "name", "type", "default", "min", "max", "unit",
						"mutable", NULL }, true, "7" },
	[K_TIMING] = { "timing", K_COMPONENT,
		       (const char *const[]){ "period", "deadline", "wcet", "priority", "cpus",
					      "exclusive", NULL }, false, "8" },
	[K_RESOURCES] = { "resources", K_COMPONENT,
			  (const char *const[]){ "memory", "network", NULL }, false, "9" },
	[K_CRITICALITY] = { "criticality", K_COMPONENT, (const char *const[]){ NULL }, true,
			    "10" },
	[K_FAULT] = { "fault", K_COMPONENT,
		      (const char *const[]){ "restart", "intensity", "window", "backoff", "safe",
					     "heartbeatTimeout", "orphanHold", NULL }, false,
		      "11" },
	[K_UPDATE] = { "update", K_COMPONENT, (const char *const[]){ "url", "sha256", NULL },
		       false, "12" },
	[K_STATE] = { "state", K_COMPONENT, (const char *const[]){ "type", "typeVersion", NULL },
		      false, "12.1" },
	[K_CONVERTS_FROM] = { "convertsFrom", K_STATE,
			      (const char *const[]){ "type", "typeVersion", NULL }, false, "12.1" },
};

struct loader {
	XML_Parser p;
	const char *path;
	char *err;
	size_t errlen;
	bool failed;
	struct arflex_host_contract *c;
	const struct arflex_host_type *types;
	unsigned ntypes;

	int stack[MAX_DEPTH];
	int depth;
	unsigned elements;
	unsigned seen;          /* bit per kind: children of <component> seen */
	bool bind_seen;         /* in the current <in> */
	char text[64];          /* <criticality> */
	size_t textlen;
	unsigned long root_line, root_col;

	int task;               /* enum arflex_task_type, -1 before <implementation> */
	bool moves_hw;
	bool has_period, has_wcet, has_priority;
	uint64_t period, deadline, wcet;
	unsigned long timing_line, timing_col;
	uint64_t hb_ms, orphan_ms;
	unsigned long fault_line, fault_col;
	bool has_safety_input;
};

/* ---- errors --------------------------------------------------------------------------- */

static void vfail_at(struct loader *L, unsigned long line, unsigned long col, const char *sec,
		     const char *field, const char *fmt, va_list ap)
{
	char what[400];

	if (L->failed)
		return;
	L->failed = true;
	vsnprintf(what, sizeof(what), fmt, ap);
	if (L->err && L->errlen)
		snprintf(L->err, L->errlen, "%s:%lu:%lu: [§%s] %s: %s", L->path, line, col, sec,
			 field, what);
	else
		fprintf(stderr, "arflex host: %s:%lu:%lu: [§%s] %s: %s\n", L->path, line, col, sec,
			field, what);
	if (L->p)
		XML_StopParser(L->p, XML_FALSE);
}

__attribute__((format(printf, 6, 7)))
static void fail_at(struct loader *L, unsigned long line, unsigned long col, const char *sec,
		    const char *field, const char *fmt, ...)
{
	va_list ap;

	va_start(ap, fmt);
	vfail_at(L, line, col, sec, field, fmt, ap);
	va_end(ap);
}

/* At the current parse position: in a start handler, the start tag of the element. */
__attribute__((format(printf, 4, 5)))
static void fail(struct loader *L, const char *sec, const char *field, const char *fmt, ...)
{
	va_list ap;

	va_start(ap, fmt);
	vfail_at(L, XML_GetCurrentLineNumber(L->p), XML_GetCurrentColumnNumber(L->p) + 1, sec,
		 field, fmt, ap);
	va_end(ap);
}

/* ---- values (SPEC 1.2, 8.1) ----------------------------------------------------------- */

static bool xml_space(char ch)
{
	return ch == ' ' || ch == '\t' || ch == '\n' || ch == '\r';
}

/* Copies @s without surrounding white space into @buf; false if it does not fit. */
static bool trimmed(const char *s, char *buf, size_t size)
{
	size_t n;

	while (xml_space(*s))
		s++;
	n = strlen(s);
	while (n && xml_space(s[n - 1]))
		n--;
	if (n >= size)
		return false;
	memcpy(buf, s, n);
	buf[n] = '\0';
	return true;
}

static size_t digits(const char *s)
{
	size_t n = 0;

	while (s[n] >= '0' && s[n] <= '9')
		n++;
	return n;
}

/* [+-]?([0-9]+(\.[0-9]*)?|\.[0-9]+)([eE][+-]?[0-9]{1,3})?, finite. */
static bool parse_decimal(const char *s, double *out)
{
	char buf[128], *end;
	const char *q;
	size_t n, f = 0;
	double d;

	if (!trimmed(s, buf, sizeof(buf)))
		return false;
	q = buf + (buf[0] == '+' || buf[0] == '-');
	n = digits(q);
	q += n;
	if (*q == '.') {
		f = digits(q + 1);
		q += 1 + f;
	}
	if (n == 0 && f == 0)
		return false;
	if (*q == 'e' || *q == 'E') {
		q++;
		q += *q == '+' || *q == '-';
		n = digits(q);
		if (n < 1 || n > 3)
			return false;
		q += n;
	}
	if (*q)
		return false;
	errno = 0;
	d = strtod(buf, &end);
	if (*end || !isfinite(d))
		return false;
	*out = d;
	return true;
}

/* [+-]?[0-9]{1,19} in int64 range. */
static bool parse_int(const char *s, int64_t *out)
{
	char buf[64], *end;
	const char *q;
	size_t n;
	long long v;

	if (!trimmed(s, buf, sizeof(buf)))
		return false;
	q = buf + (buf[0] == '+' || buf[0] == '-');
	n = digits(q);
	if (n < 1 || n > 19 || q[n])
		return false;
	errno = 0;
	v = strtoll(buf, &end, 10);
	if (errno || *end)
		return false;
	*out = v;
	return true;
}

static bool parse_bool(const char *s, bool *out)
{
	if (!strcmp(s, "true"))
		*out = true;
	else if (!strcmp(s, "false"))
		*out = false;
	else
		return false;
	return true;
}

/* [0-9]{1,15}(ns|us|ms|s) in ns, without overflow. */
static bool parse_duration(const char *s, uint64_t *out)
{
	char buf[64];
	size_t n;
	uint64_t v, mul;

	if (!trimmed(s, buf, sizeof(buf)))
		return false;
	n = digits(buf);
	if (n < 1 || n > 15)
		return false;
	if (!strcmp(buf + n, "ns"))
		mul = 1;
	else if (!strcmp(buf + n, "us"))
		mul = 1000;
	else if (!strcmp(buf + n, "ms"))
		mul = MS;
	else if (!strcmp(buf + n, "s"))
		mul = SEC;
	else
		return false;
	v = strtoull(buf, NULL, 10);
	if (v > INT64_MAX / mul)
		return false;
	*out = v * mul;
	return true;
}

static bool is_lower(char ch) { return ch >= 'a' && ch <= 'z'; }
static bool is_upper(char ch) { return ch >= 'A' && ch <= 'Z'; }
static bool is_digit(char ch) { return ch >= '0' && ch <= '9'; }

/* @s is one character of @first then at most @max - 1 of @rest. */
static bool name_ok(const char *s, bool (*first)(char), bool (*rest)(char), size_t max)
{
	size_t n;

	if (!first(s[0]))
		return false;
	for (n = 1; s[n]; n++)
		if (n >= max || !rest(s[n]))
			return false;
	return true;
}

static bool component_first(char ch) { return is_lower(ch); }
static bool component_rest(char ch) { return is_lower(ch) || is_digit(ch) || ch == '-'; }
static bool port_rest(char ch) { return is_lower(ch) || is_digit(ch) || ch == '_'; }
static bool prop_rest(char ch) { return port_rest(ch) || ch == '.'; }
static bool exe_first(char ch) { return is_lower(ch) || is_upper(ch) || is_digit(ch); }
static bool exe_rest(char ch) { return exe_first(ch) || ch == '_' || ch == '.' || ch == '-'; }

/* MAJOR.MINOR.PATCH, no leading zeros, optional -pre.release (SPEC 3.2). */
static bool semver_ok(const char *s)
{
	for (int part = 0; part < 3; part++) {
		size_t n = digits(s);

		if (n < 1 || n > 9 || (n > 1 && s[0] == '0'))
			return false;
		s += n;
		if (part < 2 && *s++ != '.')
			return false;
	}
	if (!*s)
		return true;
	if (*s++ != '-' || !*s)
		return false;
	for (; *s; s++)
		if (!exe_first(*s) && *s != '-' && !(*s == '.' && s[1] && s[1] != '.'))
			return false;
	return true;
}

/* ---- attributes ----------------------------------------------------------------------- */

static const char *attr(const XML_Char **atts, const char *name)
{
	for (int i = 0; atts[i]; i += 2)
		if (!strcmp(atts[i], name))
			return atts[i + 1];
	return NULL;
}

/* A required attribute, or NULL after reporting it missing. */
static const char *required(struct loader *L, const XML_Char **atts, const char *sec,
			    const char *where, const char *name)
{
	const char *v = attr(atts, name);

	if (!v) {
		char field[96];

		snprintf(field, sizeof(field), "%s/@%s", where, name);
		fail(L, sec, field, "required attribute missing");
	}
	return v;
}

/* An optional bool attribute; false after reporting a bad value. */
static bool opt_bool(struct loader *L, const XML_Char **atts, const char *sec,
		     const char *where, const char *name, bool *out)
{
	const char *v = attr(atts, name);
	char field[96];

	if (!v || parse_bool(v, out))
		return true;
	snprintf(field, sizeof(field), "%s/@%s", where, name);
	fail(L, sec, field, "bad bool '%s' (true or false)", v);
	return false;
}

/* An optional duration attribute in whole ms within [@lo, @hi] ns; false after a report. */
static bool opt_ms(struct loader *L, const XML_Char **atts, const char *sec, const char *name,
		   uint64_t lo, uint64_t hi, uint64_t *out_ms)
{
	const char *v = attr(atts, name);
	char field[64];
	uint64_t ns;

	if (!v)
		return true;
	snprintf(field, sizeof(field), "fault/@%s", name);
	if (!parse_duration(v, &ns)) {
		fail(L, "8.1", field, "bad duration '%s' (<integer>ns|us|ms|s)", v);
		return false;
	}
	if (ns % MS || ns < lo || ns > hi) {
		fail(L, sec, field, "%s is not whole milliseconds in %" PRIu64 "ms..%" PRIu64 "ms",
		     v, lo / MS, hi / MS);
		return false;
	}
	*out_ms = ns / MS;
	return true;
}

/* ---- elements ------------------------------------------------------------------------- */

static void on_component(struct loader *L, const XML_Char **atts)
{
	const char *name = required(L, atts, "3.1", "component", "name");
	const char *version = name ? required(L, atts, "3.2", "component", "version") : NULL;

	if (!version)
		return;
	if (!name_ok(name, component_first, component_rest, 48))
		fail(L, "3.1", "component/@name", "'%s' is not [a-z][a-z0-9-]{0,47}", name);
	else if (!semver_ok(version))
		fail(L, "3.2", "component/@version", "'%s' is not a version MAJOR.MINOR.PATCH",
		     version);
	else
		snprintf(L->c->name, sizeof(L->c->name), "%s", name);
}

static void on_implementation(struct loader *L, const XML_Char **atts)
{
	const char *exe = required(L, atts, "4.1", "implementation", "executable");
	const char *task = exe ? required(L, atts, "4.2", "implementation", "task") : NULL;

	if (!task)
		return;
	if (!name_ok(exe, exe_first, exe_rest, 64)) {
		fail(L, "4.1", "implementation/@executable",
		     "'%s' is not a file name [A-Za-z0-9][A-Za-z0-9_.-]{0,63}", exe);
		return;
	}
	snprintf(L->c->executable, sizeof(L->c->executable), "%s", exe);
	if (!strcmp(task, "periodic"))
		L->task = ARFLEX_TASK_PERIODIC;
	else if (!strcmp(task, "sporadic"))
		L->task = ARFLEX_TASK_SPORADIC;
	else if (!strcmp(task, "service"))
		L->task = ARFLEX_TASK_SERVICE;
	else {
		fail(L, "4.2", "implementation/@task",
		     "unknown task '%s' (periodic, sporadic or service)", task);
		return;
	}
	opt_bool(L, atts, "4.3", "implementation", "movesHardware", &L->moves_hw);
	const char *through = attr(atts, "motionThrough");
	if (through && strcmp(through, "device") && strcmp(through, "outputs"))
		fail(L, "4.3", "implementation/@motionThrough",
		     "'%s' is not where motion goes (device or outputs)", through);
	else if (through && !L->moves_hw)
		fail(L, "4.3", "implementation/@motionThrough",
		     "only a component that moves hardware (movesHardware=\"true\") says where its motion goes");
}

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
	const char *name = required(L, atts, "6.1", dir, "name");
	const char *type = name ? required(L, atts, "6.2", dir, "type") : NULL;
	const char *tv = type ? required(L, atts, "6.2", dir, "typeVersion") : NULL;
	const char *method = tv ? required(L, atts, "6.3", dir, "method") : NULL;
	const struct arflex_host_type *t = NULL;
	unsigned major, minor, bit;
	int n = 0;

	if (!method)
		return false;
	snprintf(where, sizeof(where), "ports/%s[%.32s]", dir, name);
	if (!name_ok(name, component_first, port_rest, 32)) {
		fail(L, "6.1", where, "port name '%s' is not [a-z][a-z0-9_]{0,31}", name);
		return false;
	}
	if (port_declared(L->c, name)) {
		fail(L, "6.1", where, "duplicate port '%s' (inputs and outputs share one name "
		     "space)", name);
		return false;
	}
	snprintf(field, sizeof(field), "%s/@type", where);
	if (!strncmp(type, "eval.", 5)) {
		fail(L, "6.7", field, "%s is an evaluation-only type, not bindable by components",
		     type);
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
		fail(L, "6.2", field, "unknown port type '%s' (known to this harness: %s)", type,
		     L->ntypes ? known : "none");
		return false;
	}
	snprintf(field, sizeof(field), "%s/@typeVersion", where);
	if (sscanf(tv, "%5u.%5u%n", &major, &minor, &n) != 2 || tv[n] || !is_digit(tv[0]) ||
	    !is_digit(tv[strlen(tv) - 1])) {
		fail(L, "6.2", field, "bad type version '%s' (MAJOR.MINOR)", tv);
		return false;
	}
	if (t->major != major || t->minor < minor) {
		fail(L, "6.2", field, "%s %u.%u is not compatible with the harness's definition "
		     "%u.%u (same major, minor at least the contract's)", type, major, minor,
		     t->major, t->minor);
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
		fail(L, "6.3", field, "unknown method '%s' (state, stream or frame)", method);
		return false;
	}
	bit = 1u << (*method_out - 1);
	if (!(t->methods & bit)) {
		fail(L, "6.3", field, "%s does not allow method %s (methods bits %#x: 1 state, "
		     "2 stream, 4 frame)", type, method, t->methods);
		return false;
	}
	*name_out = name;
	*type_out = t;
	return true;
}

/* <state type typeVersion> (D41): a state segment of that type when the harness's type table
 * knows it (the DRCR makes one for every such contract); a type the table does not list is
 * left to the Java validator and makes no segment (the half then publishes nothing). */
static void on_state(struct loader *L, const XML_Char **atts)
{
	const char *type = attr(atts, "type"), *ver = attr(atts, "typeVersion");
	struct arflex_host_contract *c = L->c;

	if (!type || !ver) {
		fail(L, "12.1", "state", "type and typeVersion are required");
		return;
	}
	for (unsigned i = 0; i < L->ntypes; i++) {
		if (strcmp(L->types[i].name, type))
			continue;
		if (!(L->types[i].methods & 1u)) {
			fail(L, "12.1", "state/@type", "port type %s does not allow the state method",
			     type);
			return;
		}
		c->state.name = L->types[i].name;
		c->state.major = L->types[i].major;
		c->state.minor = L->types[i].minor;
		c->state.elem_size = L->types[i].size;
		c->has_state = true;
	}
}

static void on_out(struct loader *L, const XML_Char **atts)
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
		fail(L, "6", "ports/out", "more than %u outputs (what rt-core holds)",
		     ARFLEX_MAX_OUTPUTS);
		return;
	}
	depth = attr(atts, "depth");
	overflow = attr(atts, "overflow");
	snprintf(field, sizeof(field), "ports/out[%s]/@depth", name);
	if (depth && !parse_int(depth, &d)) {
		fail(L, "6.4", field, "bad number '%s' (an integer)", depth);
		return;
	}
	if (method == ARFLEX_PORT_STATE && d != 1) {
		fail(L, "6.4", field, "a state output has depth 1, not %" PRId64, d);
		return;
	}
	if (method != ARFLEX_PORT_STATE && !depth) {
		fail(L, "6.4", field, "required for a %s output",
		     method == ARFLEX_PORT_STREAM ? "stream" : "frame");
		return;
	}
	if (d < 1 || d > (method == ARFLEX_PORT_FRAME ? 256 : 65536)) {
		fail(L, "6.4", field, "depth %" PRId64 " not in 1..%d", d,
		     method == ARFLEX_PORT_FRAME ? 256 : 65536);
		return;
	}
	snprintf(field, sizeof(field), "ports/out[%s]/@overflow", name);
	if (overflow && method != ARFLEX_PORT_STREAM) {
		fail(L, "6.4", field, "only on stream outputs");
		return;
	}
	if (overflow && strcmp(overflow, "drop-oldest") && strcmp(overflow, "drop-newest")) {
		fail(L, "6.4", field, "unknown overflow '%s' (drop-oldest or drop-newest)",
		     overflow);
		return;
	}
	if ((uint64_t)t->size + t->max_payload > ARFLEX_PORT_MAX_ELEM) {
		fail(L, "6.2", field, "%s: element of %" PRIu64 " bytes is too large", t->name,
		     (uint64_t)t->size + t->max_payload);
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

static void on_in(struct loader *L, const XML_Char **atts)
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
	if (!opt_bool(L, atts, "6.5", where, "optional", &optional) ||
	    !opt_bool(L, atts, "6.8", where, "safety", &safety))
		return;
	if (c->ninputs >= ARFLEX_MAX_INPUTS) {
		fail(L, "6", "ports/in", "more than %u inputs (what rt-core holds)",
		     ARFLEX_MAX_INPUTS);
		return;
	}
	if (safety && strcmp(t->name, "arflex.SafetyState")) {
		fail(L, "6.8", where, "a safety input carries arflex.SafetyState, not %s",
		     t->name);
		return;
	}
	if (safety && attr(atts, "optional") && !optional) {
		fail(L, "6.8", where, "a safety input is optional; optional=\"false\" refused");
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

static void on_bind(struct loader *L, const XML_Char **atts)
{
	if (L->bind_seen) {
		fail(L, "6.5", "ports/in/bind", "at most one <bind> per input");
		return;
	}
	L->bind_seen = true;
	if (attr(atts, "filter") && (attr(atts, "component") || attr(atts, "port")))
		fail(L, "6.5", "ports/in/bind", "either component and port, or a filter");
	else if (!attr(atts, "filter") && (!attr(atts, "component") || !attr(atts, "port")))
		fail(L, "6.5", "ports/in/bind", "component and port come together");
}

static void on_property(struct loader *L, const XML_Char **atts)
{
	struct arflex_host_contract *c = L->c;
	const char *name = required(L, atts, "7.1", "properties/property", "name");
	const char *type = name ? required(L, atts, "7.2", "properties/property", "type") : NULL;
	const char *def = type ? required(L, atts, "7.2", "properties/property", "default")
			       : NULL;
	const char *min = attr(atts, "min"), *max = attr(atts, "max");
	struct arflex_param_slot *s;
	char where[64], field[96];
	bool mutable_ = false;

	if (!def)
		return;
	snprintf(where, sizeof(where), "properties/property[%.31s]", name);
	if (!name_ok(name, component_first, prop_rest, 31)) {
		fail(L, "7.1", where, "property name '%s' is not [a-z][a-z0-9_.]{0,30}", name);
		return;
	}
	for (unsigned i = 0; i < c->nparams; i++)
		if (!strcmp(c->params[i].name, name)) {
			fail(L, "7.1", where, "duplicate property '%s'", name);
			return;
		}
	if (c->nparams >= ARFLEX_PARAM_SLOTS) {
		fail(L, "7", where, "more than %d properties (the control block's slots)",
		     ARFLEX_PARAM_SLOTS);
		return;
	}
	if (!opt_bool(L, atts, "7.5", where, "mutable", &mutable_))
		return;
	s = &c->params[c->nparams];
	memset(s, 0, sizeof(*s));
	snprintf(s->name, sizeof(s->name), "%s", name);
	s->flags = mutable_ ? ARFLEX_PARAM_MUTABLE : 0;
	if (!strcmp(type, "bool")) {
		bool b;

		s->type = ARFLEX_PARAM_BOOL;
		if (min || max || attr(atts, "unit")) {
			fail(L, "7.3", where, "min, max and unit are refused on a bool");
			return;
		}
		snprintf(field, sizeof(field), "%s/@default", where);
		if (!parse_bool(def, &b)) {
			fail(L, "7.2", field, "bad bool '%s' (true or false)", def);
			return;
		}
		s->min_bits = 0;
		s->max_bits = 1;
		s->default_bits = b;
	} else if (!strcmp(type, "int")) {
		int64_t v, lo = INT64_MIN, hi = INT64_MAX;

		s->type = ARFLEX_PARAM_INT64;
		snprintf(field, sizeof(field), "%s/@default", where);
		if (!parse_int(def, &v)) {
			fail(L, "1.2", field, "bad number '%s' (a 64-bit integer)", def);
			return;
		}
		snprintf(field, sizeof(field), "%s/@min", where);
		if (min && !parse_int(min, &lo)) {
			fail(L, "7.3", field, "bad number '%s' (a 64-bit integer)", min);
			return;
		}
		snprintf(field, sizeof(field), "%s/@max", where);
		if (max && !parse_int(max, &hi)) {
			fail(L, "7.3", field, "bad number '%s' (a 64-bit integer)", max);
			return;
		}
		if (lo > hi || v < lo || v > hi) {
			fail(L, "7.3", where, "min <= default <= max does not hold (%" PRId64
			     " <= %" PRId64 " <= %" PRId64 ")", lo, v, hi);
			return;
		}
		s->min_bits = (uint64_t)lo;
		s->max_bits = (uint64_t)hi;
		s->default_bits = (uint64_t)v;
	} else if (!strcmp(type, "double")) {
		double v, lo = -DBL_MAX, hi = DBL_MAX;

		s->type = ARFLEX_PARAM_DOUBLE;
		snprintf(field, sizeof(field), "%s/@default", where);
		if (!parse_decimal(def, &v)) {
			fail(L, "1.2", field, "bad number '%s' (a finite decimal)", def);
			return;
		}
		snprintf(field, sizeof(field), "%s/@min", where);
		if (min && !parse_decimal(min, &lo)) {
			fail(L, "7.3", field, "bad number '%s' (a finite decimal)", min);
			return;
		}
		snprintf(field, sizeof(field), "%s/@max", where);
		if (max && !parse_decimal(max, &hi)) {
			fail(L, "7.3", field, "bad number '%s' (a finite decimal)", max);
			return;
		}
		if (lo > hi || v < lo || v > hi) {
			fail(L, "7.3", where, "min <= default <= max does not hold (%g <= %g <= %g)",
			     lo, v, hi);
			return;
		}
		s->min_bits = arflex_f64_bits(lo);
		s->max_bits = arflex_f64_bits(hi);
		s->default_bits = arflex_f64_bits(v);
	} else {
		snprintf(field, sizeof(field), "%s/@type", where);
		fail(L, "7.2", field, "unknown property type '%s' (bool, int or double)", type);
		return;
	}
	c->nparams++;
}

static void on_timing(struct loader *L, const XML_Char **atts)
{
	static const char *const names[3] = { "period", "deadline", "wcet" };
	uint64_t *dst[3] = { &L->period, &L->deadline, &L->wcet };
	const char *prio = attr(atts, "priority");
	bool exclusive;
	char field[64];

	L->timing_line = XML_GetCurrentLineNumber(L->p);
	L->timing_col = XML_GetCurrentColumnNumber(L->p) + 1;
	for (int i = 0; i < 3; i++) {
		const char *v = attr(atts, names[i]);

		snprintf(field, sizeof(field), "timing/@%s", names[i]);
		if (v && !parse_duration(v, dst[i])) {
			fail(L, "8.1", field, "bad duration '%s' (<integer>ns|us|ms|s)", v);
			return;
		}
	}
	L->has_period = attr(atts, "period") != NULL;
	L->has_wcet = attr(atts, "wcet") != NULL;
	if (!attr(atts, "deadline"))
		L->deadline = L->period;
	if (prio) {
		int64_t p;

		if (!parse_int(prio, &p) || p < 1 || p > 98) {
			fail(L, "8.3", "timing/@priority", "bad priority '%s' (an integer 1..98)",
			     prio);
			return;
		}
		L->has_priority = true;
		L->c->config.priority = (int32_t)p;
	}
	opt_bool(L, atts, "8.6", "timing", "exclusive", &exclusive);
}

static void on_fault(struct loader *L, const XML_Char **atts)
{
	const char *restart = required(L, atts, "11", "fault", "restart");
	const char *safe = restart ? required(L, atts, "11", "fault", "safe") : NULL;
	const char *intensity = attr(atts, "intensity");
	uint64_t window = 0, backoff = 0;
	int64_t n;

	if (!safe)
		return;
	L->fault_line = XML_GetCurrentLineNumber(L->p);
	L->fault_col = XML_GetCurrentColumnNumber(L->p) + 1;
	if (strcmp(restart, "permanent") && strcmp(restart, "transient") &&
	    strcmp(restart, "temporary")) {
		fail(L, "11", "fault/@restart", "unknown restart '%s' (permanent, transient or "
		     "temporary)", restart);
		return;
	}
	if (!strcmp(safe, "zero"))
		L->c->config.safe_mode = ARFLEX_SAFE_ZERO;
	else if (!strcmp(safe, "hold"))
		L->c->config.safe_mode = ARFLEX_SAFE_HOLD;
	else {
		fail(L, "11", "fault/@safe", "unknown safe output '%s' (hold or zero)", safe);
		return;
	}
	if (intensity && (!parse_int(intensity, &n) || n < 0 || n > 1000)) {
		fail(L, "11", "fault/@intensity", "bad number '%s' (an integer 0..1000)",
		     intensity);
		return;
	}
	if (opt_ms(L, atts, "11", "window", MS, 3600 * SEC, &window) &&
	    opt_ms(L, atts, "11", "backoff", 0, 60 * SEC, &backoff) &&
	    opt_ms(L, atts, "11", "heartbeatTimeout", MS, 60 * SEC, &L->hb_ms))
		opt_ms(L, atts, "11", "orphanHold", 0, 60 * SEC, &L->orphan_ms);
}

/* ---- expat handlers ------------------------------------------------------------------- */

static void XMLCALL on_start(void *ud, const XML_Char *qname, const XML_Char **atts)
{
	struct loader *L = ud;
	const char *sep = strchr(qname, NS_SEP), *local = sep ? sep + 1 : qname;
	int parent = L->depth ? L->stack[L->depth - 1] : -1, kind = -1, nattrs = 0;
	const char *pname = parent >= 0 ? ELEMS[parent].name : "document";

	if (L->failed)
		return;
	if (++L->elements > MAX_ELEMENTS) {
		fail(L, "2.1", local, "more than %d elements", MAX_ELEMENTS);
		return;
	}
	if (L->depth >= MAX_DEPTH) {
		fail(L, "2.1", local, "nested deeper than %d elements", MAX_DEPTH);
		return;
	}
	if (!sep || (size_t)(sep - qname) != strlen(CONTRACT_NS) ||
	    strncmp(qname, CONTRACT_NS, (size_t)(sep - qname))) {
		fail(L, parent < 0 ? "2.3" : "2.4", local, "element <%s> is not in the namespace "
		     CONTRACT_NS, local);
		return;
	}
	for (int k = 0; k < K_COUNT; k++)
		if (ELEMS[k].parent == parent && !strcmp(ELEMS[k].name, local))
			kind = k;
	if (kind < 0) {
		fail(L, parent < 0 ? "2.3" : "2.4", pname, parent < 0
		     ? "the root is <%s>, not <component>" : "unknown element <%s>", local);
		return;
	}
	if (parent == K_COMPONENT) {
		if (L->seen & (1u << kind)) {
			fail(L, "2.4", local, "<%s> appears twice", local);
			return;
		}
		L->seen |= 1u << kind;
	}
	for (int i = 0; atts[i]; i += 2) {
		const char *const *a = ELEMS[kind].attrs;

		while (*a && strcmp(*a, atts[i]))
			a++;
		if (!*a) {
			const char *an = strchr(atts[i], NS_SEP);

			fail(L, "2.4", local, "unknown attribute '%s'", an ? an + 1 : atts[i]);
			return;
		}
		if (strlen(atts[i + 1]) > MAX_ATTR_LEN) {
			fail(L, "2.1", local, "attribute '%s' longer than %d characters", atts[i],
			     MAX_ATTR_LEN);
			return;
		}
		if (++nattrs > MAX_ATTRS) {
			fail(L, "2.1", local, "more than %d attributes", MAX_ATTRS);
			return;
		}
	}
	L->stack[L->depth++] = kind;
	L->textlen = 0;
	switch (kind) {
	case K_COMPONENT:
		L->root_line = XML_GetCurrentLineNumber(L->p);
		L->root_col = XML_GetCurrentColumnNumber(L->p) + 1;
		on_component(L, atts);
		break;
	case K_IMPLEMENTATION:
		on_implementation(L, atts);
		break;
	case K_OUT:
		on_out(L, atts);
		break;
	case K_IN:
		on_in(L, atts);
		break;
	case K_BIND:
		on_bind(L, atts);
		break;
	case K_PROPERTY:
		on_property(L, atts);
		break;
	case K_TIMING:
		on_timing(L, atts);
		break;
	case K_FAULT:
		on_fault(L, atts);
		break;
	case K_ATTRIBUTE:
		if (!attr(atts, "name") || !attr(atts, "value"))
			fail(L, "5", "attributes/attribute", "name and value are required");
		break;
	case K_RESOURCES:
		if (!attr(atts, "memory"))
			fail(L, "9.2", "resources/@memory", "required attribute missing");
		break;
	case K_UPDATE:
		if (!attr(atts, "url") || !attr(atts, "sha256"))
			fail(L, "12", "update", "url and sha256 are required");
		break;
	case K_STATE:
		on_state(L, atts);
		break;
	case K_CONVERTS_FROM:
		if (!attr(atts, "type") || !attr(atts, "typeVersion"))
			fail(L, "12.1", "state/convertsFrom", "type and typeVersion are required");
		break;
	default:
		break;
	}
}

static void XMLCALL on_end(void *ud, const XML_Char *qname)
{
	struct loader *L = ud;
	int kind;

	(void)qname;
	if (L->failed || !L->depth)
		return;
	kind = L->stack[--L->depth];
	if (kind == K_CRITICALITY) {
		int64_t v;

		L->text[L->textlen < sizeof(L->text) ? L->textlen : sizeof(L->text) - 1] = '\0';
		if (L->textlen >= sizeof(L->text) || !parse_int(L->text, &v) || v < 0 || v > 100)
			fail(L, "10", "criticality", "bad number '%s' (an integer 0..100)", L->text);
	}
}

static void XMLCALL on_text(void *ud, const XML_Char *s, int len)
{
	struct loader *L = ud;
	int kind;

	if (L->failed || !L->depth)
		return;
	kind = L->stack[L->depth - 1];
	if (!ELEMS[kind].text) {
		for (int i = 0; i < len; i++)
			if (!xml_space(s[i])) {
				fail(L, "2.4", ELEMS[kind].name, "text is not allowed in <%s>",
				     ELEMS[kind].name);
				return;
			}
		return;
	}
	if (kind == K_CRITICALITY) {
		size_t room = L->textlen < sizeof(L->text) ? sizeof(L->text) - L->textlen : 0;
		size_t n = (size_t)len < room ? (size_t)len : room;

		if (n)
			memcpy(L->text + L->textlen, s, n);
		L->textlen += (size_t)len; /* >= sizeof(text): too long for a number */
	}
}

static void XMLCALL on_doctype(void *ud, const XML_Char *name, const XML_Char *sysid,
			       const XML_Char *pubid, int internal)
{
	(void)name;
	(void)sysid;
	(void)pubid;
	(void)internal;
	fail(ud, "2.2", "document", "a <!DOCTYPE> is refused (no DTD, no entities)");
}

static void XMLCALL on_pi(void *ud, const XML_Char *target, const XML_Char *data)
{
	(void)data;
	fail(ud, "2.2", "document", "processing instruction <?%s ...?> refused", target);
}

/* ---- the whole document --------------------------------------------------------------- */

/* Reads @path (at most MAX_FILE bytes) into a new buffer. Returns 0 or -errno, reported. */
static int read_file(struct loader *L, char **buf, size_t *len)
{
	struct stat st;
	ssize_t n;
	size_t got = 0;
	int fd, r = 0;

	fd = open(L->path, O_RDONLY | O_CLOEXEC);
	if (fd < 0) {
		r = -errno;
		fail_at(L, 0, 0, "2.1", "file", "cannot open: %s", strerror(-r));
		return r;
	}
	if (fstat(fd, &st) < 0) {
		r = -errno;
		fail_at(L, 0, 0, "2.1", "file", "cannot stat: %s", strerror(-r));
	} else if (!S_ISREG(st.st_mode)) {
		r = -EINVAL;
		fail_at(L, 0, 0, "2.1", "file", "not a regular file");
	} else if ((uint64_t)st.st_size > MAX_FILE) {
		r = -EINVAL;
		fail_at(L, 0, 0, "2.1", "file", "%lld bytes, larger than 1 MiB",
			(long long)st.st_size);
	} else if (!(*buf = malloc((size_t)st.st_size + 1))) {
		r = -ENOMEM;
		fail_at(L, 0, 0, "2.1", "file", "out of memory");
	}
	while (!r && got < (size_t)st.st_size) {
		n = read(fd, *buf + got, (size_t)st.st_size - got);
		if (n < 0 && errno == EINTR)
			continue;
		if (n <= 0) {
			r = n < 0 ? -errno : -EIO;
			fail_at(L, 0, 0, "2.1", "file", "cannot read: %s", strerror(-r));
			free(*buf);
			*buf = NULL;
		} else {
			got += (size_t)n;
		}
	}
	close(fd);
	*len = got;
	return r;
}

/* The rules between elements, once the document is read. */
static void check_whole(struct loader *L)
{
	struct arflex_ctl_config *cfg = &L->c->config;
	unsigned long line = L->root_line, col = L->root_col;
	static const struct { int kind; const char *sec; } req[] = {
		{ K_IMPLEMENTATION, "4" }, { K_RESOURCES, "9" }, { K_CRITICALITY, "10" },
		{ K_FAULT, "11" },
	};

	for (size_t i = 0; i < sizeof(req) / sizeof(req[0]); i++)
		if (!(L->seen & (1u << req[i].kind))) {
			fail_at(L, line, col, req[i].sec, ELEMS[req[i].kind].name,
				"required element <%s> missing", ELEMS[req[i].kind].name);
			return;
		}
	if (L->task != ARFLEX_TASK_SERVICE) {
		if (!(L->seen & (1u << K_TIMING))) {
			fail_at(L, line, col, "8", "timing", "required for a periodic or sporadic "
				"task");
			return;
		}
		line = L->timing_line;
		col = L->timing_col;
		if (!L->has_period || !L->has_wcet || !L->has_priority) {
			fail_at(L, line, col, "8", "timing", "period, wcet and priority are required "
				"for a periodic or sporadic task");
			return;
		}
	} else if (L->seen & (1u << K_TIMING)) {
		line = L->timing_line;
		col = L->timing_col;
		if (L->has_priority) {
			fail_at(L, line, col, "8.5", "timing/@priority", "refused on a service");
			return;
		}
		if (L->has_period != L->has_wcet) {
			fail_at(L, line, col, "8.5", "timing", "period and wcet come together on a "
				"service, or not at all");
			return;
		}
	}
	if (L->has_period && (L->period == 0 || L->period > 60 * SEC || L->wcet == 0 ||
			      L->wcet > L->deadline || L->deadline > L->period)) {
		fail_at(L, line, col, "8.2", "timing", "impossible timing: 0 < wcet (%" PRIu64
			"ns) <= deadline (%" PRIu64 "ns) <= period (%" PRIu64 "ns) <= 60s does "
			"not hold", L->wcet, L->deadline, L->period);
		return;
	}
	if (L->task != ARFLEX_TASK_SERVICE && L->hb_ms * MS < L->period) {
		fail_at(L, L->fault_line, L->fault_col, "11", "fault/@heartbeatTimeout",
			"%" PRIu64 "ms is shorter than the period (%" PRIu64 "ns)", L->hb_ms,
			L->period);
		return;
	}
	if (L->moves_hw && !L->has_safety_input) {
		fail_at(L, L->root_line, L->root_col, "4.3", "implementation/@movesHardware",
			"a component that moves hardware declares a safety input");
		return;
	}
	/* As the DRCR's ControlSetup.config (the CPU is admission's: none here). */
	cfg->period_ns = L->has_period ? L->period : 0;
	cfg->deadline_ns = L->has_period ? L->deadline : 0;
	cfg->hb_timeout_ns = L->hb_ms * MS;
	cfg->cpu_mask = 0;
	if (L->task == ARFLEX_TASK_SERVICE)
		cfg->priority = 0;
	cfg->task_type = (uint32_t)L->task;
	cfg->cfg_flags = (L->moves_hw ? ARFLEX_CFG_MOVES_HARDWARE : 0) |
			 (L->task == ARFLEX_TASK_SERVICE ? ARFLEX_CFG_NO_MLOCK : 0);
	cfg->param_count = L->c->nparams;
	cfg->orphan_hold_ns = L->orphan_ms * MS;
}

int arflex_host_load_contract(struct arflex_host_contract *c, const char *path,
			      const struct arflex_host_type *types, unsigned ntypes, char *err,
			      size_t errlen)
{
	struct loader L;
	char *buf = NULL;
	size_t len = 0;
	int r;

	memset(&L, 0, sizeof(L));
	L.path = path ? path : "(null)";
	L.err = err;
	L.errlen = errlen;
	L.c = c;
	L.types = types;
	L.ntypes = types ? ntypes : 0;
	L.task = -1;
	L.hb_ms = 100;          /* SPEC 11 defaults */
	L.orphan_ms = 2000;
	if (err && errlen)
		err[0] = '\0';
	if (!c || !path) {
		fail_at(&L, 0, 0, "2", "arguments", "no contract storage or path");
		return -EINVAL;
	}
	memset(c, 0, sizeof(*c));
	r = read_file(&L, &buf, &len);
	if (r)
		goto out;
	L.p = XML_ParserCreateNS(NULL, NS_SEP);
	if (!L.p) {
		fail_at(&L, 0, 0, "2", "file", "out of memory (expat)");
		r = -ENOMEM;
		goto out;
	}
	XML_SetUserData(L.p, &L);
	XML_SetElementHandler(L.p, on_start, on_end);
	XML_SetCharacterDataHandler(L.p, on_text);
	XML_SetStartDoctypeDeclHandler(L.p, on_doctype);
	XML_SetProcessingInstructionHandler(L.p, on_pi);
	XML_SetParamEntityParsing(L.p, XML_PARAM_ENTITY_PARSING_NEVER);
	if (XML_Parse(L.p, buf, (int)len, XML_TRUE) == XML_STATUS_ERROR && !L.failed)
		fail_at(&L, XML_GetCurrentLineNumber(L.p), XML_GetCurrentColumnNumber(L.p) + 1,
			"2.1", "document", "malformed XML: %s",
			XML_ErrorString(XML_GetErrorCode(L.p)));
	if (!L.failed)
		check_whole(&L);
	r = L.failed ? -EINVAL : 0;
out:
	if (L.p)
		XML_ParserFree(L.p);
	free(buf);
	if (r)
		memset(c, 0, sizeof(*c)); /* nothing half declared */
	return r;
}

void arflex_host_contract_opts(struct arflex_host_contract *c, const char *runtime,
			       const char *instance, struct arflex_host_opts *o)
{
	memset(o, 0, sizeof(*o));
	o->runtime = runtime;
	o->instance = instance;
	o->config = c->config;
	o->params = c->nparams ? c->params : NULL;
	o->nparams = c->nparams;
	for (unsigned i = 0; i < c->noutputs; i++)
		c->outputs[i].port = c->output_ports[i];
	o->outputs = c->noutputs ? c->outputs : NULL;
	o->noutputs = c->noutputs;
	o->state = c->has_state ? &c->state : NULL;
}

const struct arflex_host_input *arflex_host_contract_input(const struct arflex_host_contract *c,
							    const char *port)
{
	for (unsigned i = 0; c && port && i < c->ninputs; i++)
		if (!strcmp(c->inputs[i].port, port))
			return &c->inputs[i];
	return NULL;
}
