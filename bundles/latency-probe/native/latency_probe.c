/*
 * latency-probe: RT half of the latency-probe component (latency benchmark, issue 5).
 *
 * Contract (bundles/latency-probe/src/main/resources/OSGI-INF/arflex/latency-probe.xml must
 * agree):
 *   ports
 *     out  samples  arflex.Sample 1.0, method stream (depth and overflow set by the contract:
 *                   65536, drop-newest; the probe works with any depth and either policy)
 *   parameters      none
 *   timing          1 ms period, SCHED_FIFO priority and CPU from the contract
 *
 * Every cycle it pushes one arflex.Sample onto `samples`:
 *   seq   = 1, 2, 3, ... one per cycle run by this process (gaps in what a reader gets are
 *           drops, never skipped cycles: an overrun's skipped periods show in t_ns instead)
 *   t_ns  = planned release of the cycle (CLOCK_MONOTONIC ns)
 *   value = wake-up lateness in ns = CLOCK_MONOTONIC at the entry of update - planned release.
 *
 * The lateness is read at the entry of update, so it includes the work rt-core's loop does
 * between the wake-up and update (statistics seqlock, parameter and binding pickup at the
 * cycle boundary, heartbeat): it is the lateness the component's own code sees. The control
 * block's latency statistics (wake-up measured by the loop itself) are the cross-check.
 * The signed period deviation follows from two consecutive samples:
 * (t_ns[i] + value[i]) - (t_ns[i-1] + value[i-1]) - period.
 *
 * Nothing here blocks, allocates or prints after configure; a refused push (ring full under
 * drop-newest) is counted by the port (hdr.dropped), not by the probe.
 */
#include <errno.h>
#include <stdint.h>
#include <stdio.h>

#include "arflex/component.h"

#include "sample_type.h"

struct probe {
	struct arflex_port *samples;
	uint64_t seq; /* samples pushed so far by this process (kept across STOP/START) */
};

static int probe_configure(struct arflex_component *c, void *user)
{
	struct probe *p = user;
	int ret;

	ret = arflex_component_output(c, "samples", ARFLEX_PORT_STREAM, &sample_port_type,
				      &p->samples);
	if (ret < 0) {
		fprintf(stderr, "latency-probe: output port 'samples' (stream %s %u.%u): error %d\n",
			sample_port_type.name, sample_port_type.major, sample_port_type.minor, ret);
		return ret;
	}
	return 0;
}

static int probe_update(struct arflex_component *c, void *user, uint64_t release_ns)
{
	struct probe *p = user;
	uint64_t now = arflex_sys_now_ns();
	struct arflex_sample s = {
		.seq = ++p->seq,
		.t_ns = (int64_t)release_ns,
		.value = (double)((int64_t)now - (int64_t)release_ns),
	};
	int ret;

	(void)c;
	ret = arflex_stream_push(p->samples, &s, sizeof(s));
	return ret < 0 ? ret : 0;
}

int main(int argc, char **argv)
{
	static struct probe p;
	static const struct arflex_component_ops ops = {
		.name = "latency-probe",
		.user = &p,
		.configure = probe_configure,
		.update = probe_update,
	};

	return arflex_component_main(argc, argv, &ops);
}
