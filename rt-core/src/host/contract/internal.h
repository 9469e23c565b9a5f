/* rt-core internal: the state of the C contract reader (arflex/host_contract.h) shared by the
 * files of src/host/contract/. Not installed, not API. The reader is one pass of expat over the
 * document (xml.c) that hands each element to the file of its part of the format; the first
 * problem is reported (report.c) and stops the parse; contract.c then checks the rules between
 * elements and fills in the control block's configuration. */
#ifndef ARFLEX_HOST_CONTRACT_INTERNAL_H
#define ARFLEX_HOST_CONTRACT_INTERNAL_H

#include <expat.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "arflex/host_contract.h"

#define MAX_DEPTH 16            /* SPEC 2.1; the other limits are xml.c's and contract.c's */
#define MS UINT64_C(1000000)
#define SEC UINT64_C(1000000000)

enum kind {
	K_COMPONENT, K_DESCRIPTION, K_IMPLEMENTATION, K_ATTRIBUTES, K_ATTRIBUTE, K_PORTS, K_IN,
	K_OUT, K_BIND, K_PROPERTIES, K_PROPERTY, K_TIMING, K_RESOURCES, K_CRITICALITY, K_FAULT,
	K_UPDATE, K_STATE, K_CONVERTS_FROM, K_COUNT
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

/* ---- report.c: the first problem, and attributes ----------------------------------------- */

/* Reports "path:line:col: [§sec] field: message" into the caller's buffer (or on stderr) and
 * stops the parse; only the first report of a document counts. */
void arflex_hc_fail_at(struct loader *L, unsigned long line, unsigned long col, const char *sec,
		       const char *field, const char *fmt, ...)
	__attribute__((format(printf, 6, 7)));
/* The same at the current parse position: in a start handler, the start tag of the element. */
void arflex_hc_fail(struct loader *L, const char *sec, const char *field, const char *fmt, ...)
	__attribute__((format(printf, 4, 5)));
/* The value of attribute @name, or NULL. */
const char *arflex_hc_attr(const XML_Char **atts, const char *name);
/* A required attribute, or NULL after reporting "<where>/@<name>" missing. */
const char *arflex_hc_required(struct loader *L, const XML_Char **atts, const char *sec,
			       const char *where, const char *name);
/* An optional bool attribute; false after reporting a bad value. */
bool arflex_hc_opt_bool(struct loader *L, const XML_Char **atts, const char *sec,
			const char *where, const char *name, bool *out);

/* ---- values.c: lexical values (SPEC 1.2, 3, 4.1, 6, 7.1, 8.1) ------------------------------ */

bool arflex_hc_xml_space(char ch);
bool arflex_hc_parse_decimal(const char *s, double *out);  /* finite decimal */
bool arflex_hc_parse_int(const char *s, int64_t *out);     /* 64-bit integer */
bool arflex_hc_parse_bool(const char *s, bool *out);       /* true | false */
bool arflex_hc_parse_duration(const char *s, uint64_t *out); /* <integer>ns|us|ms|s, in ns */
bool arflex_hc_parse_type_version(const char *s, unsigned *major, unsigned *minor);
bool arflex_hc_component_name_ok(const char *s); /* [a-z][a-z0-9-]{0,47} */
bool arflex_hc_semver_ok(const char *s);         /* MAJOR.MINOR.PATCH[-pre.release] */
bool arflex_hc_executable_ok(const char *s);     /* [A-Za-z0-9][A-Za-z0-9_.-]{0,63} */
bool arflex_hc_port_name_ok(const char *s);      /* [a-z][a-z0-9_]{0,31} */
bool arflex_hc_property_name_ok(const char *s);  /* [a-z][a-z0-9_.]{0,30} */

/* ---- the elements, at their start tag (after xml.c checked names and attributes) --------- */

/* implementation.c: <component>, <implementation>, <attribute>, <resources>, <update> */
void arflex_hc_on_component(struct loader *L, const XML_Char **atts);
void arflex_hc_on_implementation(struct loader *L, const XML_Char **atts);
void arflex_hc_on_attribute(struct loader *L, const XML_Char **atts);
void arflex_hc_on_resources(struct loader *L, const XML_Char **atts);
void arflex_hc_on_update(struct loader *L, const XML_Char **atts);
/* ports.c: <in>, <out>, <bind> */
void arflex_hc_on_out(struct loader *L, const XML_Char **atts);
void arflex_hc_on_in(struct loader *L, const XML_Char **atts);
void arflex_hc_on_bind(struct loader *L, const XML_Char **atts);
/* properties.c: <property> */
void arflex_hc_on_property(struct loader *L, const XML_Char **atts);
/* timing.c: <timing>, <fault> */
void arflex_hc_on_timing(struct loader *L, const XML_Char **atts);
void arflex_hc_on_fault(struct loader *L, const XML_Char **atts);
/* state.c: <state>, <convertsFrom> (D41) */
void arflex_hc_on_state(struct loader *L, const XML_Char **atts);
void arflex_hc_on_converts_from(struct loader *L, const XML_Char **atts);

/* ---- xml.c: the document ------------------------------------------------------------------- */

/* Parses @buf with expat into L->p (the caller frees it), each element handed to the
 * functions above. Returns -ENOMEM (reported) when expat cannot start, else 0: a problem
 * found is in L->failed. */
int arflex_hc_read_xml(struct loader *L, const char *buf, size_t len);
/* The element's name in the format ("component", "timing", ...). */
const char *arflex_hc_elem_name(enum kind kind);

#endif /* ARFLEX_HOST_CONTRACT_INTERNAL_H */
