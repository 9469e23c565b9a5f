/*
 * pi_velocity.c - a LEGACY-STYLE real-time control loop, the starting point of the porting
 * example in ../GUIDE.md. It is written the way such loops often are, on purpose:
 * globals, while (1), its own relative sleep, printf in the loop, constants for parameters.
 *
 * A PI velocity controller drives a simulated first-order plant (a motor: velocity follows
 * PLANT_GAIN * u with time constant PLANT_TAU). Usage: pi_velocity [cycles] (0 or none: run
 * forever).
 */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#define PERIOD_NS 1000000L /* 1 ms */
#define DT 0.001           /* s, must match PERIOD_NS */
#define U_MAX 5.0          /* actuator limit */
#define PLANT_GAIN 2.0
#define PLANT_TAU 0.05     /* s */

/* tuning and command */
double kp = 1.0;
double ki = 15.0;
double setpoint = 1.0;     /* rad/s */

/* controller and plant state */
double integral;
double velocity;           /* the "sensor" */
double u;                  /* the "actuator" command */
long cycle;
long saturated;

/* The hardware: apply u for one period and let the velocity respond. */
static void plant_step(double cmd)
{
	velocity += DT / PLANT_TAU * (PLANT_GAIN * cmd - velocity);
}

static void control_step(void)
{
	double e = setpoint - velocity;

	integral += e * DT;
	u = kp * e + ki * integral;
	if (u > U_MAX || u < -U_MAX) {
		u = u > 0 ? U_MAX : -U_MAX;
		integral -= e * DT; /* anti-windup: undo the integration */
		saturated++;
		printf("cycle %ld: actuator saturated\n", cycle);
	}
	plant_step(u);
}

int main(int argc, char **argv)
{
	long cycles = argc > 1 ? atol(argv[1]) : 0;
	struct timespec period = { 0, PERIOD_NS };

	while (1) {
		control_step();
		if (cycle % 500 == 0)
			printf("cycle %ld: velocity %.6f u %.6f\n", cycle, velocity, u);
		cycle++;
		if (cycles && cycle >= cycles)
			break;
		clock_nanosleep(CLOCK_MONOTONIC, 0, &period, NULL); /* relative: drifts */
	}
	printf("done after %ld cycles: velocity %.6f (setpoint %.6f), %ld saturations\n",
	       cycle, velocity, setpoint, saturated);
	return 0;
}
