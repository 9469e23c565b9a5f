/* The contract reader's one report (the first problem of a document, in the Java validator's
 * "file:line:column: [§N] field: message" form) and the attribute getters that report. */
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "internal.h"

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

void arflex_hc_fail_at(struct loader *L, unsigned long line, unsigned long col, const char *sec,
		       const char *field, const char *fmt, ...)
{
	va_list ap;

	va_start(ap, fmt);
	vfail_at(L, line, col, sec, field, fmt, ap);
	va_end(ap);
}

void arflex_hc_fail(struct loader *L, const char *sec, const char *field, const char *fmt, ...)
{
	va_list ap;

	va_start(ap, fmt);
	vfail_at(L, XML_GetCurrentLineNumber(L->p), XML_GetCurrentColumnNumber(L->p) + 1, sec,
		 field, fmt, ap);
	va_end(ap);
}

const char *arflex_hc_attr(const XML_Char **atts, const char *name)
{
	for (int i = 0; atts[i]; i += 2)
		if (!strcmp(atts[i], name))
			return atts[i + 1];
	return NULL;
}

const char *arflex_hc_required(struct loader *L, const XML_Char **atts, const char *sec,
			       const char *where, const char *name)
{
	const char *v = arflex_hc_attr(atts, name);

	if (!v) {
		char field[96];

		snprintf(field, sizeof(field), "%s/@%s", where, name);
		arflex_hc_fail(L, sec, field, "required attribute missing");
	}
	return v;
}

bool arflex_hc_opt_bool(struct loader *L, const XML_Char **atts, const char *sec,
			const char *where, const char *name, bool *out)
{
	const char *v = arflex_hc_attr(atts, name);
	char field[96];

	if (!v || arflex_hc_parse_bool(v, out))
		return true;
	snprintf(field, sizeof(field), "%s/@%s", where, name);
	arflex_hc_fail(L, sec, field, "bad bool '%s' (true or false)", v);
	return false;
}
