/* The contract reader's XML layer: the element table of the format, the expat handlers that
 * check namespace, nesting, limits, attributes and text (SPEC 2) and hand each element to the
 * file of its part, and the parse of the whole buffer. DOCTYPE and processing instructions are
 * refused (no DTD, no entities). */
#include <errno.h>
#include <string.h>

#include "internal.h"

#define CONTRACT_NS "urn:arflex:contract:1"
#define NS_SEP '|'
#define MAX_ELEMENTS 10000      /* SPEC 2.1 */
#define MAX_ATTRS 32
#define MAX_ATTR_LEN 4096

/* Every element of the format: its name, its parent, its attributes, whether text is
 * allowed in it. */
static const struct elem {
	const char *name;
	int parent;             /* -1: the root */
	const char *const *attrs;
	bool text;
} ELEMS[K_COUNT] = {
	[K_COMPONENT] = { "component", -1, (const char *const[]){ "name", "version", NULL },
			  false },
	[K_DESCRIPTION] = { "description", K_COMPONENT, (const char *const[]){ NULL }, true },
	[K_IMPLEMENTATION] = { "implementation", K_COMPONENT,
			       (const char *const[]){ "executable", "task", "movesHardware",
						      "motionThrough", NULL }, false },
	[K_ATTRIBUTES] = { "attributes", K_COMPONENT, (const char *const[]){ NULL }, false },
	[K_ATTRIBUTE] = { "attribute", K_ATTRIBUTES, (const char *const[]){ "name", "value", NULL },
			  false },
	[K_PORTS] = { "ports", K_COMPONENT, (const char *const[]){ NULL }, false },
	[K_IN] = { "in", K_PORTS,
		   (const char *const[]){ "name", "type", "typeVersion", "method", "optional",
					  "safety", NULL }, false },
	[K_OUT] = { "out", K_PORTS,
		    (const char *const[]){ "name", "type", "typeVersion", "method", "depth",
					   "overflow", NULL }, false },
	[K_BIND] = { "bind", K_IN, (const char *const[]){ "component", "port", "filter", NULL },
		     false },
	[K_PROPERTIES] = { "properties", K_COMPONENT, (const char *const[]){ NULL }, false },
	[K_PROPERTY] = { "property", K_PROPERTIES,
			 (const char *const[]){ "name", "type", "default", "min", "max", "unit",
						"mutable", NULL }, true },
	[K_TIMING] = { "timing", K_COMPONENT,
		       (const char *const[]){ "period", "deadline", "wcet", "priority", "cpus",
					      "exclusive", NULL }, false },
	[K_RESOURCES] = { "resources", K_COMPONENT,
			  (const char *const[]){ "memory", "network", NULL }, false },
	[K_CRITICALITY] = { "criticality", K_COMPONENT, (const char *const[]){ NULL }, true },
	[K_FAULT] = { "fault", K_COMPONENT,
		      (const char *const[]){ "restart", "intensity", "window", "backoff", "safe",
					     "heartbeatTimeout", "orphanHold", NULL }, false },
	[K_UPDATE] = { "update", K_COMPONENT, (const char *const[]){ "url", "sha256", NULL },
		       false },
	[K_STATE] = { "state", K_COMPONENT, (const char *const[]){ "type", "typeVersion", NULL },
		      false },
	[K_CONVERTS_FROM] = { "convertsFrom", K_STATE,
			      (const char *const[]){ "type", "typeVersion", NULL }, false },
};

/* ---- expat handlers ------------------------------------------------------------------- */

/* Every element: in the namespace, where the format puts it, at most once under <component>,
 * only its own attributes, within the limits of SPEC 2.1; then handed to its part's file. */
static void XMLCALL on_start(void *ud, const XML_Char *qname, const XML_Char **atts)
{
	struct loader *L = ud;
	const char *sep = strchr(qname, NS_SEP), *local = sep ? sep + 1 : qname;
	int parent = L->depth ? L->stack[L->depth - 1] : -1, kind = -1, nattrs = 0;
	const char *pname = parent >= 0 ? ELEMS[parent].name : "document";

	if (L->failed)
		return;
	if (++L->elements > MAX_ELEMENTS) {
		arflex_hc_fail(L, "2.1", local, "more than %d elements", MAX_ELEMENTS);
		return;
	}
	if (L->depth >= MAX_DEPTH) {
		arflex_hc_fail(L, "2.1", local, "nested deeper than %d elements", MAX_DEPTH);
		return;
	}
	if (!sep || (size_t)(sep - qname) != strlen(CONTRACT_NS) ||
	    strncmp(qname, CONTRACT_NS, (size_t)(sep - qname))) {
		arflex_hc_fail(L, parent < 0 ? "2.3" : "2.4", local,
			       "element <%s> is not in the namespace " CONTRACT_NS, local);
		return;
	}
	for (int k = 0; k < K_COUNT; k++)
		if (ELEMS[k].parent == parent && !strcmp(ELEMS[k].name, local))
			kind = k;
	if (kind < 0) {
		arflex_hc_fail(L, parent < 0 ? "2.3" : "2.4", pname, parent < 0
			       ? "the root is <%s>, not <component>" : "unknown element <%s>",
			       local);
		return;
	}
	if (parent == K_COMPONENT) {
		if (L->seen & (1u << kind)) {
			arflex_hc_fail(L, "2.4", local, "<%s> appears twice", local);
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

			arflex_hc_fail(L, "2.4", local, "unknown attribute '%s'",
				       an ? an + 1 : atts[i]);
			return;
		}
		if (strlen(atts[i + 1]) > MAX_ATTR_LEN) {
			arflex_hc_fail(L, "2.1", local, "attribute '%s' longer than %d characters",
				       atts[i], MAX_ATTR_LEN);
			return;
		}
		if (++nattrs > MAX_ATTRS) {
			arflex_hc_fail(L, "2.1", local, "more than %d attributes", MAX_ATTRS);
			return;
		}
	}
	L->stack[L->depth++] = kind;
	L->textlen = 0;
	switch (kind) {
	case K_COMPONENT:
		L->root_line = XML_GetCurrentLineNumber(L->p);
		L->root_col = XML_GetCurrentColumnNumber(L->p) + 1;
		arflex_hc_on_component(L, atts);
		break;
	case K_IMPLEMENTATION:
		arflex_hc_on_implementation(L, atts);
		break;
	case K_OUT:
		arflex_hc_on_out(L, atts);
		break;
	case K_IN:
		arflex_hc_on_in(L, atts);
		break;
	case K_BIND:
		arflex_hc_on_bind(L, atts);
		break;
	case K_PROPERTY:
		arflex_hc_on_property(L, atts);
		break;
	case K_TIMING:
		arflex_hc_on_timing(L, atts);
		break;
	case K_FAULT:
		arflex_hc_on_fault(L, atts);
		break;
	case K_ATTRIBUTE:
		arflex_hc_on_attribute(L, atts);
		break;
	case K_RESOURCES:
		arflex_hc_on_resources(L, atts);
		break;
	case K_UPDATE:
		arflex_hc_on_update(L, atts);
		break;
	case K_STATE:
		arflex_hc_on_state(L, atts);
		break;
	case K_CONVERTS_FROM:
		arflex_hc_on_converts_from(L, atts);
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
		if (L->textlen >= sizeof(L->text) || !arflex_hc_parse_int(L->text, &v) || v < 0 ||
		    v > 100)
			arflex_hc_fail(L, "10", "criticality",
				       "bad number '%s' (an integer 0..100)", L->text);
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
			if (!arflex_hc_xml_space(s[i])) {
				arflex_hc_fail(L, "2.4", ELEMS[kind].name,
					       "text is not allowed in <%s>", ELEMS[kind].name);
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
	arflex_hc_fail(ud, "2.2", "document", "a <!DOCTYPE> is refused (no DTD, no entities)");
}

static void XMLCALL on_pi(void *ud, const XML_Char *target, const XML_Char *data)
{
	(void)data;
	arflex_hc_fail(ud, "2.2", "document", "processing instruction <?%s ...?> refused",
		       target);
}

const char *arflex_hc_elem_name(enum kind kind)
{
	return ELEMS[kind].name;
}

int arflex_hc_read_xml(struct loader *L, const char *buf, size_t len)
{
	L->p = XML_ParserCreateNS(NULL, NS_SEP);
	if (!L->p) {
		arflex_hc_fail_at(L, 0, 0, "2", "file", "out of memory (expat)");
		return -ENOMEM;
	}
	XML_SetUserData(L->p, L);
	XML_SetElementHandler(L->p, on_start, on_end);
	XML_SetCharacterDataHandler(L->p, on_text);
	XML_SetStartDoctypeDeclHandler(L->p, on_doctype);
	XML_SetProcessingInstructionHandler(L->p, on_pi);
	XML_SetParamEntityParsing(L->p, XML_PARAM_ENTITY_PARSING_NEVER);
	if (XML_Parse(L->p, buf, (int)len, XML_TRUE) == XML_STATUS_ERROR && !L->failed)
		arflex_hc_fail_at(L, XML_GetCurrentLineNumber(L->p),
				  XML_GetCurrentColumnNumber(L->p) + 1, "2.1", "document",
				  "malformed XML: %s", XML_ErrorString(XML_GetErrorCode(L->p)));
	return 0;
}
