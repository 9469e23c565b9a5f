/* The contract reader's <timing> (SPEC 8: period, deadline, wcet, priority) and <fault>
 * (SPEC 11: restart, safe output, heartbeat timeout, orphan hold). What they mean together is
 * checked once the document is read (contract.c). */
#include <inttypes.h>
#include <stdio.h>
#include <string.h>

#include "internal.h"

/* An optional duration attribute of <fault> in whole ms within [@lo, @hi] ns; false after a
 * report. */
static bool opt_ms(struct loader *L, const XML_Char **atts, const char *sec, const char *name,
		   uint64_t lo, uint64_t hi, uint64_t *out_ms)
{
	const char *v = arflex_hc_attr(atts, name);
	char field[64];
	uint64_t ns;

	if (!v)
		return true;
	snprintf(field, sizeof(field), "fault/@%s", name);
	if (!arflex_hc_parse_duration(v, &ns)) {
		arflex_hc_fail(L, "8.1", field, "bad duration '%s' (<integer>ns|us|ms|s)", v);
		return false;
	}
	if (ns % MS || ns < lo || ns > hi) {
		arflex_hc_fail(L, sec, field,
			       "%s is not whole milliseconds in %" PRIu64 "ms..%" PRIu64 "ms", v,
			       lo / MS, hi / MS);
		return false;
	}
	*out_ms = ns / MS;
	return true;
}

void arflex_hc_on_timing(struct loader *L, const XML_Char **atts)
{
	static const char *const names[3] = { "period", "deadline", "wcet" };
	uint64_t *dst[3] = { &L->period, &L->deadline, &L->wcet };
	const char *prio = arflex_hc_attr(atts, "priority");
	bool exclusive;
	char field[64];

	L->timing_line = XML_GetCurrentLineNumber(L->p);
	L->timing_col = XML_GetCurrentColumnNumber(L->p) + 1;
	for (int i = 0; i < 3; i++) {
		const char *v = arflex_hc_attr(atts, names[i]);

		snprintf(field, sizeof(field), "timing/@%s", names[i]);
		if (v && !arflex_hc_parse_duration(v, dst[i])) {
			arflex_hc_fail(L, "8.1", field, "bad duration '%s' (<integer>ns|us|ms|s)",
				       v);
			return;
		}
	}
	L->has_period = arflex_hc_attr(atts, "period") != NULL;
	L->has_wcet = arflex_hc_attr(atts, "wcet") != NULL;
	if (!arflex_hc_attr(atts, "deadline"))
		L->deadline = L->period;
	if (prio) {
		int64_t p;

		if (!arflex_hc_parse_int(prio, &p) || p < 1 || p > 98) {
			arflex_hc_fail(L, "8.3", "timing/@priority",
				       "bad priority '%s' (an integer 1..98)", prio);
			return;
		}
		L->has_priority = true;
		L->c->config.priority = (int32_t)p;
	}
	arflex_hc_opt_bool(L, atts, "8.6", "timing", "exclusive", &exclusive);
}

void arflex_hc_on_fault(struct loader *L, const XML_Char **atts)
{
	const char *restart = arflex_hc_required(L, atts, "11", "fault", "restart");
	const char *safe = restart ? arflex_hc_required(L, atts, "11", "fault", "safe") : NULL;
	const char *intensity = arflex_hc_attr(atts, "intensity");
	uint64_t window = 0, backoff = 0;
	int64_t n;

	if (!safe)
		return;
	L->fault_line = XML_GetCurrentLineNumber(L->p);
	L->fault_col = XML_GetCurrentColumnNumber(L->p) + 1;
	if (strcmp(restart, "permanent") && strcmp(restart, "transient") &&
	    strcmp(restart, "temporary")) {
		arflex_hc_fail(L, "11", "fault/@restart", "unknown restart '%s' (permanent, "
			       "transient or temporary)", restart);
		return;
	}
	if (!strcmp(safe, "zero"))
		L->c->config.safe_mode = ARFLEX_SAFE_ZERO;
	else if (!strcmp(safe, "hold"))
		L->c->config.safe_mode = ARFLEX_SAFE_HOLD;
	else {
		arflex_hc_fail(L, "11", "fault/@safe", "unknown safe output '%s' (hold or zero)",
			       safe);
		return;
	}
	if (intensity && (!arflex_hc_parse_int(intensity, &n) || n < 0 || n > 1000)) {
		arflex_hc_fail(L, "11", "fault/@intensity", "bad number '%s' (an integer 0..1000)",
			       intensity);
		return;
	}
	if (opt_ms(L, atts, "11", "window", MS, 3600 * SEC, &window) &&
	    opt_ms(L, atts, "11", "backoff", 0, 60 * SEC, &backoff) &&
	    opt_ms(L, atts, "11", "heartbeatTimeout", MS, 60 * SEC, &L->hb_ms))
		opt_ms(L, atts, "11", "orphanHold", 0, 60 * SEC, &L->orphan_ms);
}
