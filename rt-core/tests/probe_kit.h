/* The probe fixture shared by the process-level component tests (test_component.c,
 * test_supervisor.c): ids and environment, a host for the probe RT half, reading its output,
 * waiting on conditions with deadlines. Needs cmocka. */
#ifndef ARFLEX_PROBE_KIT_H
#define ARFLEX_PROBE_KIT_H

#include <stdbool.h>
#include <stdint.h>

#include "arflex/host.h"

#define SEC 1000000000ull
#define T_CALL (5 * SEC)

struct probe_out {
	uint64_t updates, safe_calls, safe_firsts;
	int64_t gain;
	uint64_t torn, in_value, in_reads, in_bound, in_binding;
	uint64_t adopt_calls, adopted; /* D41: adopt hook calls, the (converted) value adopted */
	uint64_t state_value;          /* what it publishes as its state block (adopted + updates) */
	uint64_t prepare_calls, prepared; /* D57: the ADOPT's prepare hook, the value it saw */
};
/* The probe's state block (D41): test.ProbeState 1.0, one uint64. It converts
 * test.OldProbeState 0.x (value x 10) and refuses any other type. */
extern const struct arflex_port_type probe_state_type;
/* true: the next probe_host creates the probe's state segment */
extern bool probe_state;

extern const struct arflex_port_type value_type;
extern char rid[64];
extern char logpath[128];
extern char *envp[256];
/* priority, CPU mask and orphan hold for the next probe_host */
extern int probe_prio;
extern uint64_t probe_cpus;
extern uint64_t probe_hold;
extern uint32_t probe_task_type; /* enum arflex_task_type */

void make_env(const char *extra);
void setup_ids(const char *tag);
int probe_host(struct arflex_host *h, const char *inst, uint64_t hb_timeout, uint32_t cfg_flags,
	       bool with_out);
bool read_out(struct arflex_host *h, struct probe_out *o);
typedef bool (*pred_fn)(const struct probe_out *o, uint64_t arg);
/* Waits (with a deadline, not a sleep) until @pred holds on the probe's output; keeps the
 * runtime heartbeat fresh when @hb. Dumps the last output on expiry. */
bool wait_out(struct arflex_host *h, pred_fn pred, uint64_t arg, bool hb);
bool updates_above(const struct probe_out *o, uint64_t n);
bool safe_above(const struct probe_out *o, uint64_t n);
bool gain_is(const struct probe_out *o, uint64_t g);
bool in_is(const struct probe_out *o, uint64_t v);
bool unbound(const struct probe_out *o, uint64_t v);
bool binding_is(const struct probe_out *o, uint64_t b);
uint64_t binding_of(struct arflex_host *h);
void spawn_ready(struct arflex_host *h);
void shutdown_ok(struct arflex_host *h);
/* The end of a case: each probe shut down cleanly (shutdown_ok) and destroyed, the log removed,
 * nothing of the rid left (th_assert_clean). */
void finish_probes(struct arflex_host *const *hosts, size_t n);
#define FINISH_PROBES(...)                                                                    \
	finish_probes((struct arflex_host *const[]){ __VA_ARGS__ },                           \
		      sizeof((struct arflex_host *const[]){ __VA_ARGS__ }) / sizeof(struct arflex_host *))

#endif
