/* trace.h - the legacy and the ported PI loop stepped cycle by cycle on the same inputs. */
#ifndef ARFLEX_TEMPLATE_TRACE_H
#define ARFLEX_TEMPLATE_TRACE_H

#include <stdint.h>

struct trace_inputs {
	double kp, ki;
	double setpoint;       /* from cycle 0 */
	long change_at;        /* the cycle from which setpoint_after applies */
	double setpoint_after;
};

/* The state after the step of one cycle. */
struct trace_step {
	double velocity, u;
	long saturated;
};

void trace_legacy(long n, const struct trace_inputs *in, struct trace_step *out);
void trace_ported(long n, const struct trace_inputs *in, uint64_t period_ns, struct trace_step *out);

#endif
