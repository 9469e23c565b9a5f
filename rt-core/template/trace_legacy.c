/*
 * trace_legacy.c - the legacy loop's own step (legacy/pi_velocity.c, compiled as it is, its
 * main renamed), run cycle by cycle without its sleep, for test_template's comparison of the
 * ported loop with the legacy one (rt.template.legacy and rt.template.ported).
 */
#define main legacy_main
#include "legacy/pi_velocity.c"
#undef main

#include "trace.h"

void trace_legacy(long n, const struct trace_inputs *in, struct trace_step *out)
{
	integral = velocity = u = 0.0;
	cycle = saturated = 0;
	kp = in->kp;
	ki = in->ki;
	for (long i = 0; i < n; i++) {
		setpoint = i < in->change_at ? in->setpoint : in->setpoint_after;
		control_step();
		out[i].velocity = velocity;
		out[i].u = u;
		out[i].saturated = saturated;
		cycle++;
	}
}
