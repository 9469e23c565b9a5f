/*
 * debug-monitor - RT half of the debug monitor component: observes state ports of other
 * components without disturbing them and republishes what it sees on its own ports.
 *
 * Generic by construction: the RT half does not know which components it watches. It has up
 * to DM_SLOTS monitor slots; slot k exists when the manager created the output port
 * "m<k>_last" (that is, when the contract declares it). For an existing slot it declares the
 * input "m<k>" (state, arflex.Sample; the contract binds it, explicitly or by filter) and
 * opens, when the contract declares them, the outputs "m<k>_min", "m<k>_max", "m<k>_mean".
 *
 * Every cycle, for each slot with a new input value:
 *   - m<k>_last gets the observed sample verbatim (same seq, t_ns, value);
 *   - the value joins the current window; when the window holds `window` values, m<k>_min,
 *     m<k>_max and m<k>_mean are published for it (seq = number of completed windows, t_ns =
 *     t_ns of the window's last value) and a new window begins.
 * An unbound input (its provider went away) holds the outputs and drops the partial window.
 * A change of `window` drops the partial windows of every slot.
 *
 * Reading a state port never writes the provider's segment, so the monitored components
 * cannot tell whether a monitor is attached. Stream and frame inputs are refused on purpose:
 * a stream has a single consumer and a monitor must not consume.
 */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include "arflex/component.h"
#include "arflex_types/sample.h"

#define DM_SLOTS 4 /* 4 outputs per slot, ARFLEX_MAX_OUTPUTS = 16 */

static const struct arflex_port_type dm_sample_type = {
	.name = ARFLEX_TYPE_SAMPLE_NAME,
	.major = ARFLEX_TYPE_SAMPLE_VERSION_MAJOR,
	.minor = ARFLEX_TYPE_SAMPLE_VERSION_MINOR,
	.elem_size = ARFLEX_TYPE_SAMPLE_SIZE,
};

enum dm_stat { DM_MIN, DM_MAX, DM_MEAN, DM_NSTATS };
static const char *const dm_stat_names[DM_NSTATS] = { "min", "max", "mean" };

struct dm_slot {
	bool present;
	struct arflex_input *in;
	struct arflex_port *last;
	struct arflex_port *stat[DM_NSTATS]; /* NULL: not declared by the contract */
	/* current window */
	uint64_t n;
	double min, max, sum;
	int64_t t_last;
	uint64_t windows; /* completed windows */
};

struct dm {
	struct dm_slot slot[DM_SLOTS];
	unsigned nslots;
	int p_window;
	int64_t window; /* value in force for the current windows */
};

static void dm_window_reset(struct dm_slot *s)
{
	s->n = 0;
	s->min = INFINITY;
	s->max = -INFINITY;
	s->sum = 0.0;
}

/* Whether the manager created output port @port (the contract declares it). Probed first so
 * that an absent optional port is not reported as an error by arflex_component_output. */
static bool dm_output_exists(struct arflex_component *c, const char *port)
{
	char name[ARFLEX_OBJ_NAME_SIZE];
	int fd;

	snprintf(name, sizeof(name), "/arflex.%s.%s.out.%s", arflex_component_runtime(c),
		 arflex_component_instance(c), port);
	fd = shm_open(name, O_RDONLY, 0);
	if (fd < 0)
		return false;
	close(fd);
	return true;
}

static int dm_configure(struct arflex_component *c, void *user)
{
	struct dm *m = user;
	char name[32];
	int ret;

	m->p_window = arflex_component_param(c, "window");
	if (m->p_window < 0) {
		fprintf(stderr, "debug-monitor: parameter 'window' missing from the control block\n");
		return -ENOENT;
	}
	for (unsigned k = 0; k < DM_SLOTS; k++) {
		struct dm_slot *s = &m->slot[k];

		snprintf(name, sizeof(name), "m%u_last", k);
		if (!dm_output_exists(c, name))
			continue; /* slot not declared by the contract */
		ret = arflex_component_output(c, name, ARFLEX_PORT_STATE, &dm_sample_type, &s->last);
		if (ret < 0) {
			fprintf(stderr, "debug-monitor: output port '%s' (state %s): error %d\n",
				name, dm_sample_type.name, ret);
			return ret;
		}
		for (unsigned j = 0; j < DM_NSTATS; j++) {
			snprintf(name, sizeof(name), "m%u_%s", k, dm_stat_names[j]);
			s->stat[j] = NULL;
			if (!dm_output_exists(c, name))
				continue;
			ret = arflex_component_output(c, name, ARFLEX_PORT_STATE, &dm_sample_type,
						      &s->stat[j]);
			if (ret < 0) {
				fprintf(stderr,
					"debug-monitor: output port '%s' (state %s): error %d\n",
					name, dm_sample_type.name, ret);
				return ret;
			}
		}
		snprintf(name, sizeof(name), "m%u", k);
		ret = arflex_component_input(c, name, ARFLEX_PORT_STATE, &dm_sample_type, &s->in);
		if (ret < 0) {
			fprintf(stderr, "debug-monitor: input port '%s' (state %s): error %d\n", name,
				dm_sample_type.name, ret);
			return ret;
		}
		s->present = true;
		m->nslots++;
	}
	if (m->nslots == 0) {
		fprintf(stderr, "debug-monitor: the contract declares no monitor slot (no output "
				"port m0_last .. m%u_last)\n", DM_SLOTS - 1);
		return -EINVAL;
	}
	return 0;
}

static int dm_start(struct arflex_component *c, void *user)
{
	struct dm *m = user;

	m->window = arflex_param_i64(c, m->p_window);
	for (unsigned k = 0; k < DM_SLOTS; k++)
		dm_window_reset(&m->slot[k]);
	return 0;
}

static int dm_publish_window(struct dm_slot *s)
{
	double v[DM_NSTATS];
	int err = 0;

	v[DM_MIN] = s->min;
	v[DM_MAX] = s->max;
	v[DM_MEAN] = s->sum / (double)s->n;
	s->windows++;
	for (unsigned j = 0; j < DM_NSTATS; j++) {
		struct arflex_sample o = { .seq = s->windows, .t_ns = s->t_last, .value = v[j] };
		int ret;

		if (!s->stat[j])
			continue;
		ret = arflex_state_write(s->stat[j], &o, sizeof(o));
		if (ret < 0)
			err = ret;
	}
	dm_window_reset(s);
	return err;
}

static int dm_update(struct arflex_component *c, void *user, uint64_t release_ns)
{
	struct dm *m = user;
	int64_t window = arflex_param_i64(c, m->p_window);
	int err = 0;

	(void)release_ns;
	if (window != m->window) {
		m->window = window;
		for (unsigned k = 0; k < DM_SLOTS; k++)
			dm_window_reset(&m->slot[k]);
	}
	for (unsigned k = 0; k < DM_SLOTS; k++) {
		struct dm_slot *s = &m->slot[k];
		struct arflex_sample in;
		int ret;

		if (!s->present)
			continue;
		ret = arflex_input_state_read(s->in, &in, sizeof(in), NULL);
		if (ret == -ENOTCONN) {
			dm_window_reset(s); /* hold the outputs, drop the partial window */
			continue;
		}
		if (ret < 0) {
			err = ret;
			continue;
		}
		if (ret == 0)
			continue; /* nothing new */
		ret = arflex_state_write(s->last, &in, sizeof(in));
		if (ret < 0)
			err = ret;
		if (in.value < s->min)
			s->min = in.value;
		if (in.value > s->max)
			s->max = in.value;
		s->sum += in.value;
		s->t_last = in.t_ns;
		if (++s->n >= (uint64_t)m->window) {
			ret = dm_publish_window(s);
			if (ret < 0)
				err = ret;
		}
	}
	return err;
}

int main(int argc, char **argv)
{
	static struct dm m;
	static const struct arflex_component_ops ops = {
		.name = "debug-monitor",
		.user = &m,
		.configure = dm_configure,
		.start = dm_start,
		.update = dm_update,
	};

	return arflex_component_main(argc, argv, &ops);
}
