/*
 * trace_ported.c - the ported component's step (ported/pi_velocity.c, compiled as it is, its
 * main renamed), run cycle by cycle with the parameters its update hook would read, for
 * test_template's comparison with the legacy loop.
 */
#define main ported_main
#include "ported/pi_velocity.c"
#undef main

#include "trace.h"

void trace_ported(long n, const struct trace_inputs *in, uint64_t period_ns, struct trace_step *out)
{
	static struct pi s;

	s = (struct pi){ 0 };
	s.dt = (double)period_ns * 1e-9; /* as pi_configure computes it from the control block */
	for (long i = 0; i < n; i++) {
		control_step(&s, in->kp, in->ki, i < in->change_at ? in->setpoint : in->setpoint_after);
		out[i].velocity = s.velocity;
		out[i].u = s.u;
		out[i].saturated = s.saturated;
		s.cycle++;
	}
}
