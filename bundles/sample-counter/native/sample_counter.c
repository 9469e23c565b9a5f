/*
 * sample-counter: RT half of the sample-counter component (a signal source).
 *
 * Contract (bundles/sample-counter/src/main/resources/OSGI-INF/arflex/sample-counter.xml must
 * agree):
 *   ports
 *     out  count   arflex.Sample 1.0, method state
 *   parameters
 *     amplitude    double   peak value of the sine
 *     frequency    double   Hz
 *   safe           hold (the safe hook follows config.safe_mode: hold = stop writing,
 *                  zero = publish value 0 every cycle)
 *
 * Every period it writes one arflex.Sample to `count`:
 *   seq   = 1, 2, 3, ... (one per sample written by this process)
 *   t_ns  = planned release time of the cycle (CLOCK_MONOTONIC ns)
 *   value = amplitude * sin(2 pi frequency t), t = seconds since the first START.
 */
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>

#include "arflex/component.h"

#include "sample_type.h"

#define SAMPLE_PI 3.14159265358979323846

struct counter {
	struct arflex_port *count;
	int p_amplitude;
	int p_frequency;
	uint64_t seq;     /* samples written so far */
	uint64_t t0_ns;   /* release of the first cycle after the first START */
	bool have_t0;
};

static int counter_configure(struct arflex_component *c, void *user)
{
	struct counter *k = user;
	int ret;

	k->p_amplitude = arflex_component_param(c, "amplitude");
	k->p_frequency = arflex_component_param(c, "frequency");
	if (k->p_amplitude < 0 || k->p_frequency < 0) {
		fprintf(stderr, "sample-counter: parameter '%s' missing from the control block\n",
			k->p_amplitude < 0 ? "amplitude" : "frequency");
		return -ENOENT;
	}
	ret = arflex_component_output(c, "count", ARFLEX_PORT_STATE, &sample_port_type, &k->count);
	if (ret < 0) {
		fprintf(stderr, "sample-counter: output port 'count' (state %s): error %d\n",
			sample_port_type.name, ret);
		return ret;
	}
	return 0;
}

static int counter_publish(struct counter *k, uint64_t release_ns, double value)
{
	struct arflex_sample s = {
		.seq = ++k->seq,
		.t_ns = (int64_t)release_ns,
		.value = value,
	};

	return arflex_state_write(k->count, &s, sizeof(s));
}

static int counter_update(struct arflex_component *c, void *user, uint64_t release_ns)
{
	struct counter *k = user;
	double amp = arflex_param_f64(c, k->p_amplitude);
	double freq = arflex_param_f64(c, k->p_frequency);
	double t;

	if (!k->have_t0) {
		k->t0_ns = release_ns;
		k->have_t0 = true;
	}
	t = (double)(release_ns - k->t0_ns) * 1e-9;
	return counter_publish(k, release_ns, amp * sin(2.0 * SAMPLE_PI * freq * t));
}

static int counter_safe(struct arflex_component *c, void *user, enum arflex_safe_mode mode,
			bool first)
{
	struct counter *k = user;

	(void)c;
	(void)first;
	if (mode == ARFLEX_SAFE_ZERO)
		return counter_publish(k, arflex_sys_now_ns(), 0.0);
	return 0; /* hold: the last value stays in the port */
}

int main(int argc, char **argv)
{
	static struct counter k;
	static const struct arflex_component_ops ops = {
		.name = "sample-counter",
		.user = &k,
		.configure = counter_configure,
		.update = counter_update,
		.safe = counter_safe,
	};

	return arflex_component_main(argc, argv, &ops);
}
