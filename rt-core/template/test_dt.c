/*
 * ctest rt.template.dt: the time step a ported loop computes from its period
 * (arflex_period_s, arflex/component.h) is bit-identical to the decimal constant the legacy
 * loop had (`#define DT 0.009` for a 9 ms period), at every period from 1 us to 100 ms in
 * 1 us steps, not only at 1 ms (GUIDE.md, "A bit-exact time step").
 */
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "arflex/component.h"

int main(void)
{
	unsigned long bad = 0, checked = 0;
	char lit[48];

	for (uint64_t ns = 1000; ns <= UINT64_C(100000000); ns += 1000) {
		/* the constant as a legacy source writes it, e.g. "0.009000000" */
		snprintf(lit, sizeof(lit), "%" PRIu64 ".%09" PRIu64, ns / UINT64_C(1000000000),
			 ns % UINT64_C(1000000000));
		double want = strtod(lit, NULL);
		double got = arflex_period_s(ns);
		checked++;
		if (memcmp(&want, &got, sizeof(want)) != 0) {
			if (bad++ < 5)
				fprintf(stderr, "FAIL period %" PRIu64 " ns: arflex_period_s %.17g, legacy DT %s = %.17g\n",
					ns, got, lit, want);
		}
	}
	printf("rt.template.dt: %lu of %lu periods differ from the legacy constant\n", bad, checked);
	return bad ? 1 : 0;
}
