/* The contract reader's <properties> (SPEC 7): each <property> becomes a parameter slot of the
 * control block (name, type, range, default, mutable) as the DRCR writes it. */
#include <float.h>
#include <inttypes.h>
#include <stdio.h>
#include <string.h>

#include "internal.h"

void arflex_hc_on_property(struct loader *L, const XML_Char **atts)
{
	struct arflex_host_contract *c = L->c;
	const char *const P = "properties/property";
	const char *name = arflex_hc_required(L, atts, "7.1", P, "name");
	const char *type = name ? arflex_hc_required(L, atts, "7.2", P, "type") : NULL;
	const char *def = type ? arflex_hc_required(L, atts, "7.2", P, "default") : NULL;
	const char *min = arflex_hc_attr(atts, "min"), *max = arflex_hc_attr(atts, "max");
	struct arflex_param_slot *s;
	char where[64], field[96];
	bool mutable_ = false;

	if (!def)
		return;
	snprintf(where, sizeof(where), "properties/property[%.31s]", name);
	if (!arflex_hc_property_name_ok(name)) {
		arflex_hc_fail(L, "7.1", where, "property name '%s' is not [a-z][a-z0-9_.]{0,30}",
			       name);
		return;
	}
	for (unsigned i = 0; i < c->nparams; i++)
		if (!strcmp(c->params[i].name, name)) {
			arflex_hc_fail(L, "7.1", where, "duplicate property '%s'", name);
			return;
		}
	if (c->nparams >= ARFLEX_PARAM_SLOTS) {
		arflex_hc_fail(L, "7", where, "more than %d properties (the control block's slots)",
			       ARFLEX_PARAM_SLOTS);
		return;
	}
	if (!arflex_hc_opt_bool(L, atts, "7.5", where, "mutable", &mutable_))
		return;
	s = &c->params[c->nparams];
	memset(s, 0, sizeof(*s));
	snprintf(s->name, sizeof(s->name), "%s", name);
	s->flags = mutable_ ? ARFLEX_PARAM_MUTABLE : 0;
	if (!strcmp(type, "bool")) {
		bool b;

		s->type = ARFLEX_PARAM_BOOL;
		if (min || max || arflex_hc_attr(atts, "unit")) {
			arflex_hc_fail(L, "7.3", where, "min, max and unit are refused on a bool");
			return;
		}
		snprintf(field, sizeof(field), "%s/@default", where);
		if (!arflex_hc_parse_bool(def, &b)) {
			arflex_hc_fail(L, "7.2", field, "bad bool '%s' (true or false)", def);
			return;
		}
		s->min_bits = 0;
		s->max_bits = 1;
		s->default_bits = b;
	} else if (!strcmp(type, "int")) {
		int64_t v, lo = INT64_MIN, hi = INT64_MAX;

		s->type = ARFLEX_PARAM_INT64;
		snprintf(field, sizeof(field), "%s/@default", where);
		if (!arflex_hc_parse_int(def, &v)) {
			arflex_hc_fail(L, "1.2", field, "bad number '%s' (a 64-bit integer)", def);
			return;
		}
		snprintf(field, sizeof(field), "%s/@min", where);
		if (min && !arflex_hc_parse_int(min, &lo)) {
			arflex_hc_fail(L, "7.3", field, "bad number '%s' (a 64-bit integer)", min);
			return;
		}
		snprintf(field, sizeof(field), "%s/@max", where);
		if (max && !arflex_hc_parse_int(max, &hi)) {
			arflex_hc_fail(L, "7.3", field, "bad number '%s' (a 64-bit integer)", max);
			return;
		}
		if (lo > hi || v < lo || v > hi) {
			arflex_hc_fail(L, "7.3", where, "min <= default <= max does not hold "
				       "(%" PRId64 " <= %" PRId64 " <= %" PRId64 ")", lo, v, hi);
			return;
		}
		s->min_bits = (uint64_t)lo;
		s->max_bits = (uint64_t)hi;
		s->default_bits = (uint64_t)v;
	} else if (!strcmp(type, "double")) {
		double v, lo = -DBL_MAX, hi = DBL_MAX;

		s->type = ARFLEX_PARAM_DOUBLE;
		snprintf(field, sizeof(field), "%s/@default", where);
		if (!arflex_hc_parse_decimal(def, &v)) {
			arflex_hc_fail(L, "1.2", field, "bad number '%s' (a finite decimal)", def);
			return;
		}
		snprintf(field, sizeof(field), "%s/@min", where);
		if (min && !arflex_hc_parse_decimal(min, &lo)) {
			arflex_hc_fail(L, "7.3", field, "bad number '%s' (a finite decimal)", min);
			return;
		}
		snprintf(field, sizeof(field), "%s/@max", where);
		if (max && !arflex_hc_parse_decimal(max, &hi)) {
			arflex_hc_fail(L, "7.3", field, "bad number '%s' (a finite decimal)", max);
			return;
		}
		if (lo > hi || v < lo || v > hi) {
			arflex_hc_fail(L, "7.3", where, "min <= default <= max does not hold "
				       "(%g <= %g <= %g)", lo, v, hi);
			return;
		}
		s->min_bits = arflex_f64_bits(lo);
		s->max_bits = arflex_f64_bits(hi);
		s->default_bits = arflex_f64_bits(v);
	} else {
		snprintf(field, sizeof(field), "%s/@type", where);
		arflex_hc_fail(L, "7.2", field, "unknown property type '%s' (bool, int or double)",
			       type);
		return;
	}
	c->nparams++;
}
