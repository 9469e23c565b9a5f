/*
 * sample-scaler: RT half of the sample-scaler component (a one-input filter).
 *
 * Contract (bundles/sample-scaler/src/main/resources/OSGI-INF/arflex/sample-scaler.xml must
 * agree):
 *   ports
 *     in   x       arflex.Sample 1.0, method state (bound to sample-counter.count)
 *     out  y       arflex.Sample 1.0, method state; a stream segment (any depth/overflow)
 *                  is accepted too: the method is taken from the segment the manager made
 *   parameters
 *     gain         double, mutable while running; applied at a cycle boundary
 *   safe           zero (the safe hook follows config.safe_mode: zero = publish value 0 every
 *                  cycle, hold = stop writing)
 *
 * Every period: if x has a new value s, write y = { s.seq, s.t_ns, gain * s.value } (the
 * input's seq and time are carried through, so a reader can match y to x). No new value: no
 * write. Input unbound (UNBIND, or never bound): y stops changing; with safe mode "zero" one
 * sample { last seq, now, 0.0 } is written when the input goes away, then nothing.
 *
 * Validation (contracts/README.md "Valid values"): an input value that fails
 * arflex_sample_valid (NaN, infinity) is not used: update returns -EINVAL (counted in
 * stats.update_errors) and y holds the last valid value. A product that is not finite
 * (overflow) is refused the same way with -ERANGE. A damaged input header is -EPROTO from the
 * read (counted the same way, and in the ARFLEX_WARN_INPUT warning).
 */
#include <errno.h>
#include <stdint.h>
#include <stdio.h>

#include "arflex/component.h"

#include "sample_type.h"

struct scaler {
	struct arflex_input *x;
	struct arflex_port *y;
	enum arflex_port_method y_method;
	int p_gain;
	struct arflex_sample last_in; /* last input value seen */
	bool was_bound;              /* input was bound in the previous cycle */
};

static int scaler_configure(struct arflex_component *c, void *user)
{
	struct scaler *k = user;
	int ret;

	k->p_gain = arflex_component_param(c, "gain");
	if (k->p_gain < 0) {
		fprintf(stderr, "sample-scaler: parameter 'gain' missing from the control block\n");
		return -ENOENT;
	}
	ret = arflex_component_input(c, "x", ARFLEX_PORT_STATE, &sample_port_type, &k->x);
	if (ret < 0) {
		fprintf(stderr, "sample-scaler: input port 'x' (state %s): error %d\n",
			sample_port_type.name, ret);
		return ret;
	}
	k->y_method = ARFLEX_PORT_STATE;
	ret = arflex_component_output(c, "y", ARFLEX_PORT_STATE, &sample_port_type, &k->y);
	if (ret == -EPROTOTYPE) {
		k->y_method = ARFLEX_PORT_STREAM;
		ret = arflex_component_output(c, "y", ARFLEX_PORT_STREAM, &sample_port_type,
					      &k->y);
	}
	if (ret < 0) {
		fprintf(stderr, "sample-scaler: output port 'y' (%s, state or stream): error %d\n",
			sample_port_type.name, ret);
		return ret;
	}
	return 0;
}

static int scaler_emit(struct scaler *k, const struct arflex_sample *s)
{
	int ret;

	if (k->y_method == ARFLEX_PORT_STATE)
		return arflex_state_write(k->y, s, sizeof(*s));
	ret = arflex_stream_push(k->y, s, sizeof(*s));
	return ret < 0 ? ret : 0; /* a drop is counted in the segment, not an error */
}

static int scaler_emit_zero(struct scaler *k)
{
	struct arflex_sample z = {
		.seq = k->last_in.seq,
		.t_ns = (int64_t)arflex_sys_now_ns(),
		.value = 0.0,
	};

	return scaler_emit(k, &z);
}

static int scaler_start(struct arflex_component *c, void *user)
{
	struct scaler *k = user;

	(void)c;
	k->was_bound = false;
	return 0;
}

static int scaler_update(struct arflex_component *c, void *user, uint64_t release_ns)
{
	struct scaler *k = user;
	struct arflex_sample in, out;
	int ret;

	(void)release_ns;
	ret = arflex_input_state_read(k->x, &in, sizeof(in), NULL);
	if (ret == -ENOTCONN) {
		/* The input went away: hold, or publish one zero if the contract says so. */
		if (k->was_bound) {
			k->was_bound = false;
			if (arflex_component_ctl(c)->config.safe_mode == ARFLEX_SAFE_ZERO)
				return scaler_emit_zero(k);
		}
		return 0;
	}
	k->was_bound = true;
	if (ret <= 0)
		return ret; /* 0: no new value this cycle */
	if (!arflex_sample_valid(&in)) {
		arflex_input_reject(k->x); /* counted on the input: the DRCR names its provider */
		return -EINVAL;            /* not used: y holds the last valid value */
	}
	out.seq = in.seq;
	out.t_ns = in.t_ns;
	out.value = arflex_param_f64(c, k->p_gain) * in.value;
	if (!arflex_sample_valid(&out))
		return -ERANGE;
	k->last_in = in;
	return scaler_emit(k, &out);
}

static int scaler_safe(struct arflex_component *c, void *user, enum arflex_safe_mode mode,
		       bool first)
{
	struct scaler *k = user;

	(void)c;
	(void)first;
	if (mode == ARFLEX_SAFE_ZERO)
		return scaler_emit_zero(k);
	return 0; /* hold */
}

int main(int argc, char **argv)
{
	static struct scaler k;
	static const struct arflex_component_ops ops = {
		.name = "sample-scaler",
		.user = &k,
		.configure = scaler_configure,
		.start = scaler_start,
		.update = scaler_update,
		.safe = scaler_safe,
	};

	return arflex_component_main(argc, argv, &ops);
}
