/* sdk.out_of_tree: a program linked against the installed arflex::safety (and through it the
 * static arflex::rt and arflex::types) that calls into both and prints what it got. */
#include <stdio.h>

#include <arflex/safety_gate.h>
#include <arflex_types/safety_state.h>

int main(void)
{
	struct arflex_safety_gate g;
	enum arflex_safety_verdict v;

	/* No provider: the gate must say so and forbid motion. */
	arflex_safety_gate_init(&g, NULL, 100000000u);
	v = arflex_safety_gate_judge(&g, NULL, 0, arflex_sys_now_ns());
	if (v != ARFLEX_SAFETY_NO_PROVIDER || arflex_safety_permits(v))
		return 1;
	printf("%s, port name %s, %u-byte %s\n", arflex_safety_verdict_name(v),
	       arflex_port_name_valid("safety") ? "valid" : "invalid",
	       ARFLEX_TYPE_SAFETY_STATE_SIZE, ARFLEX_TYPE_SAFETY_STATE_NAME);
	return 0;
}
