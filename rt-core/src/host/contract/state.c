/* The contract reader's state block (SPEC 12.1, DECISIONS.md D41): <state type typeVersion>
 * and its <convertsFrom> children. */
#include <string.h>

#include "internal.h"

/* <state type typeVersion> (D41): a state segment of that type when the harness's type table
 * knows it (the DRCR makes one for every such contract); a type the table does not list is
 * left to the Java validator and makes no segment (the half then publishes nothing). */
void arflex_hc_on_state(struct loader *L, const XML_Char **atts)
{
	const char *type = arflex_hc_attr(atts, "type");
	const char *ver = arflex_hc_attr(atts, "typeVersion");
	struct arflex_host_contract *c = L->c;

	if (!type || !ver) {
		arflex_hc_fail(L, "12.1", "state", "type and typeVersion are required");
		return;
	}
	for (unsigned i = 0; i < L->ntypes; i++) {
		if (!L->types[i].name || strcmp(L->types[i].name, type))
			continue; /* a table entry without a name matches nothing (as for ports) */
		if (!(L->types[i].methods & 1u)) {
			arflex_hc_fail(L, "12.1", "state/@type",
				       "port type %s does not allow the state method", type);
			return;
		}
		c->state.name = L->types[i].name;
		c->state.major = L->types[i].major;
		c->state.minor = L->types[i].minor;
		c->state.elem_size = L->types[i].size;
		c->has_state = true;
	}
}

/* <convertsFrom type typeVersion>: what the adopt hook converts is the Java validator's and
 * the DRCR's plan's; here only its form. */
void arflex_hc_on_converts_from(struct loader *L, const XML_Char **atts)
{
	if (!arflex_hc_attr(atts, "type") || !arflex_hc_attr(atts, "typeVersion"))
		arflex_hc_fail(L, "12.1", "state/convertsFrom",
			       "type and typeVersion are required");
}
