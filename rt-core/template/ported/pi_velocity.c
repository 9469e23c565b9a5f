/*
 * pi_velocity.c - the legacy loop of ../legacy/pi_velocity.c PORTED to an ARFLEX component,
 * with the diff kept small. ../GUIDE.md explains each change and shows the diff.
 *
 * A PI velocity controller drives a simulated first-order plant (a motor: velocity follows
 * PLANT_GAIN * u with time constant PLANT_TAU). The plant stands for the hardware.
 *
 * Contract of this component (a bundle would carry it as XML):
 *   ports
 *     out  velocity  arflex.Sample 1.0, state: seq = cycle + 1, t_ns = release, value = velocity
 *     out  command   arflex.Sample 1.0, state: same seq and t_ns, value = u
 *   parameters (double, mutable while running, applied at a cycle boundary)
 *     kp 1.0, ki 15.0, setpoint 1.0 (rad/s)
 *   timing  period from the control block (the legacy DT constant is gone)
 *   safe    zero: u = 0 and the plant coasts; hold: the last u is kept
 */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>

#include "arflex/component.h"
#include "arflex_types/sample.h"

#define U_MAX 5.0          /* actuator limit */
#define PLANT_GAIN 2.0
#define PLANT_TAU 0.05     /* s */

/* arflex.Sample 1.0 (struct arflex_sample: u64 seq, i64 t_ns, f64 value) */
static const struct arflex_port_type sample_type = {
	ARFLEX_TYPE_SAMPLE_NAME, ARFLEX_TYPE_SAMPLE_VERSION_MAJOR, ARFLEX_TYPE_SAMPLE_VERSION_MINOR,
	ARFLEX_TYPE_SAMPLE_SIZE,
};

struct pi {
	/* tuning and command: parameter slots in the control block */
	int kp;
	int ki;
	int setpoint;      /* rad/s */

	/* controller and plant state */
	double integral;
	double velocity;   /* the "sensor" */
	double u;          /* the "actuator" command */
	long cycle;
	long saturated;

	double dt;         /* s, from the control block's period */
	struct arflex_port *velocity_out, *command_out;
};

/* The hardware: apply u for one period and let the velocity respond. */
static void plant_step(struct pi *s, double cmd)
{
	s->velocity += s->dt / PLANT_TAU * (PLANT_GAIN * cmd - s->velocity);
}

static void control_step(struct pi *s, double kp, double ki, double setpoint)
{
	double e = setpoint - s->velocity;

	s->integral += e * s->dt;
	s->u = kp * e + ki * s->integral;
	if (s->u > U_MAX || s->u < -U_MAX) {
		s->u = s->u > 0 ? U_MAX : -U_MAX;
		s->integral -= e * s->dt; /* anti-windup: undo the integration */
		s->saturated++;
	}
	plant_step(s, s->u);
}

static void publish(struct pi *s, uint64_t release_ns)
{
	struct arflex_sample v = { (uint64_t)s->cycle + 1, (int64_t)release_ns, s->velocity };
	struct arflex_sample c = { (uint64_t)s->cycle + 1, (int64_t)release_ns, s->u };

	arflex_state_write(s->velocity_out, &v, sizeof(v));
	arflex_state_write(s->command_out, &c, sizeof(c));
}

/* configure (main thread): what main() did before the loop. */
static int pi_configure(struct arflex_component *c, void *user)
{
	struct pi *s = user;
	int ret;

	s->kp = arflex_component_param(c, "kp");
	s->ki = arflex_component_param(c, "ki");
	s->setpoint = arflex_component_param(c, "setpoint");
	if (s->kp < 0 || s->ki < 0 || s->setpoint < 0) {
		fprintf(stderr, "pi-velocity: parameters kp, ki and setpoint are required\n");
		return -ENOENT;
	}
	s->dt = arflex_period_s(arflex_component_ctl(c)->config.period_ns);
	ret = arflex_component_output(c, "velocity", ARFLEX_PORT_STATE, &sample_type,
				      &s->velocity_out);
	if (ret == 0)
		ret = arflex_component_output(c, "command", ARFLEX_PORT_STATE, &sample_type,
					      &s->command_out);
	if (ret < 0)
		fprintf(stderr, "pi-velocity: output ports velocity/command: error %d\n", ret);
	return ret;
}

/* start (RT thread): a new run starts without the integral of the previous one. */
static int pi_start(struct arflex_component *c, void *user)
{
	struct pi *s = user;

	(void)c;
	s->integral = 0.0;
	return 0;
}

/* update (RT thread, every period): the body of the old while (1). */
static int pi_update(struct arflex_component *c, void *user, uint64_t release_ns)
{
	struct pi *s = user;

	control_step(s, arflex_param_f64(c, s->kp), arflex_param_f64(c, s->ki),
		     arflex_param_f64(c, s->setpoint));
	publish(s, release_ns);
	s->cycle++;
	return 0;
}

/* safe (RT thread, instead of update while the runtime is silent). */
static int pi_safe(struct arflex_component *c, void *user, enum arflex_safe_mode mode,
		   bool first)
{
	struct pi *s = user;

	(void)c;
	(void)first;
	if (mode == ARFLEX_SAFE_ZERO)
		s->u = 0.0;
	plant_step(s, s->u);
	publish(s, arflex_sys_now_ns());
	s->cycle++;
	return 0;
}

/* cleanup (main thread, before exit): the place for the final report. */
static void pi_cleanup(struct arflex_component *c, void *user)
{
	struct pi *s = user;

	(void)c;
	printf("pi-velocity: done after %ld cycles: velocity %.6f, %ld saturations\n", s->cycle,
	       s->velocity, s->saturated);
}

int main(int argc, char **argv)
{
	static struct pi s;
	static const struct arflex_component_ops ops = {
		.name = "pi-velocity",
		.user = &s,
		.configure = pi_configure,
		.start = pi_start,
		.update = pi_update,
		.stop = NULL,
		.cleanup = pi_cleanup,
		.safe = pi_safe,
	};

	return arflex_component_main(argc, argv, &ops);
}
