/*
 * template.c - the skeleton of an ARFLEX RT half. Copy it, rename "template", keep what you
 * need. It builds as it is (arflex-template): one input `in`, one output `out` (both
 * arflex.Sample, state) and one parameter `gain`; update writes out = gain * in.
 *
 * How the pieces fit (arflex/component.h has the full rules):
 *   - The manager (the DRCR, or the C host API in tests) creates every shared object before
 *     it starts this process: the control block with config and parameter table, the command
 *     and reply queues, and one segment per OUTPUT port. This process only opens them.
 *   - arflex_component_main() runs everything: arguments (--runtime, --instance), attach,
 *     configure, the mailbox thread (START, STOP, SET_PARAM, BIND, ... SHUTDOWN), the RT
 *     thread with its periodic loop, safe mode, cleanup. You write the hooks below.
 *   - Threads: configure and cleanup run on the MAIN thread; start, update, safe and stop on
 *     the RT thread. Hooks never run at the same time as each other.
 *
 * The contract (XML in the bundle) must agree with what configure declares: port names,
 * port types and methods, parameter names and types. Put that list in a comment block at
 * the top of the file, as here:
 *
 *   ports       in   in    arflex.Sample 1.0, state
 *               out  out   arflex.Sample 1.0, state
 *   parameters  gain       double, mutable
 *   safe        hold (or zero: see template_safe)
 */
#include <errno.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include "arflex/component.h"
#include "arflex_types/sample.h"

/* The C layout of each port type comes from the header generated from its definition
 * (contracts/types/<type>.xml -> contracts/include/arflex_types/, CMake target arflex_types).
 * rt-core checks every segment against this descriptor (name, version, size). */
static const struct arflex_port_type sample_type = {
	.name = ARFLEX_TYPE_SAMPLE_NAME,
	.major = ARFLEX_TYPE_SAMPLE_VERSION_MAJOR,
	.minor = ARFLEX_TYPE_SAMPLE_VERSION_MINOR,
	.elem_size = ARFLEX_TYPE_SAMPLE_SIZE,
};

/*
 * All state of the component lives in one struct (never in scattered globals): what a
 * cycle needs is here, preallocated. One instance per process; main() owns it.
 */
struct template {
	/* ports: pointers owned by the library, valid until exit */
	struct arflex_input *in;
	struct arflex_port *out;
	/* parameter slot indexes, looked up once in configure */
	int p_gain;
	/* working state */
	struct arflex_sample last;
	/* counters instead of printf in the loop; report them from cleanup */
	uint64_t no_input_cycles;
};

/*
 * configure - OPTIONAL; MAIN thread; once, before READY.
 * MAY: declare ports (arflex_component_output / arflex_component_input), look up parameters
 *      (arflex_component_param), read the control block config, allocate, open files or
 *      devices, print diagnostics to stderr.
 * MUST: return 0 or a negative errno. On error the process ends with state FAILED and
 *      cleanup is NOT called: undo what this hook did before returning the error.
 * MAY NOT: write outputs (the manager may still be wiring things), create shared objects.
 */
static int template_configure(struct arflex_component *c, void *user)
{
	struct template *t = user;
	int ret;

	t->p_gain = arflex_component_param(c, "gain");
	if (t->p_gain < 0) {
		fprintf(stderr, "template: parameter 'gain' missing from the control block\n");
		return -ENOENT;
	}
	ret = arflex_component_input(c, "in", ARFLEX_PORT_STATE, &sample_type, &t->in);
	if (ret < 0) {
		fprintf(stderr, "template: input 'in': error %d\n", ret);
		return ret;
	}
	ret = arflex_component_output(c, "out", ARFLEX_PORT_STATE, &sample_type, &t->out);
	if (ret < 0) {
		fprintf(stderr, "template: output 'out': error %d\n", ret);
		return ret;
	}
	return 0;
}

/*
 * start - OPTIONAL; RT thread (already at its priority, memory locked); at every START,
 * before the first cycle.
 * MAY: reset per-run state, touch (prefault) memory the cycle will use.
 * MUST: be short and return 0, or < 0 to refuse the START (the reply carries the error,
 *      the state stays READY).
 * MAY NOT: block, allocate, print (it runs on the RT thread).
 */
static int template_start(struct arflex_component *c, void *user)
{
	struct template *t = user;

	(void)c;
	t->last = (struct arflex_sample){ 0, 0, 0.0 };
	return 0;
}

/*
 * update - REQUIRED; RT thread; once per period. @release_ns is the planned release time
 * (CLOCK_MONOTONIC ns) of this cycle.
 * MAY: read inputs (arflex_input_state_read, _stream_pop, _frame_acquire), read parameters
 *      (arflex_param_f64/_i64/_bool: they change only between cycles), write outputs
 *      (arflex_state_write, arflex_stream_push, arflex_frame_begin/commit), update counters.
 * MUST: finish well within the period; return 0, or < 0 to count an update error (the loop
 *      goes on).
 * MAY NOT: block (locks, I/O, sleeps, waiting on another process), allocate or free, print,
 *      make system calls other than the clock, call configure-only functions.
 */
static int template_update(struct arflex_component *c, void *user, uint64_t release_ns)
{
	struct template *t = user;
	struct arflex_sample s;
	int ret = arflex_input_state_read(t->in, &s, sizeof(s), NULL);

	(void)release_ns;
	if (ret == -ENOTCONN) {           /* not bound (yet): outputs hold */
		t->no_input_cycles++;
		return 0;
	}
	if (ret <= 0)
		return ret;               /* 0: no new value this cycle */
	t->last = s;
	s.value *= arflex_param_f64(c, t->p_gain);
	return arflex_state_write(t->out, &s, sizeof(s));
}

/*
 * stop - OPTIONAL; RT thread; after the last cycle of a run (STOP, SHUTDOWN, SIGTERM).
 * MAY: bring outputs to a resting value, like the safe hook would.
 * MAY NOT: block, allocate, print.
 */
static void template_stop(struct arflex_component *c, void *user)
{
	(void)c;
	(void)user;
}

/*
 * safe - OPTIONAL (REQUIRED in practice when the component moves hardware); RT thread;
 * every cycle while the runtime's heartbeat is lost, INSTEAD of update. @first is true on
 * the first call of an episode. @mode is the contract's safe mode:
 *   ARFLEX_SAFE_HOLD: keep outputs at their last value (often: do nothing);
 *   ARFLEX_SAFE_ZERO: drive outputs to zero / neutral.
 * Same rules as update. Without a safe hook, outputs simply stop changing.
 */
static int template_safe(struct arflex_component *c, void *user, enum arflex_safe_mode mode,
			 bool first)
{
	struct template *t = user;
	struct arflex_sample z = { t->last.seq, (int64_t)arflex_sys_now_ns(), 0.0 };

	(void)c;
	(void)first;
	if (mode == ARFLEX_SAFE_ZERO)
		return arflex_state_write(t->out, &z, sizeof(z));
	return 0;
}

/*
 * cleanup - OPTIONAL; MAIN thread; once before exit, only if configure succeeded.
 * MAY: free what configure allocated, close devices, print the final counters.
 * MAY NOT: touch ports after returning (the library unmaps them next).
 */
static void template_cleanup(struct arflex_component *c, void *user)
{
	struct template *t = user;

	fprintf(stderr, "template %s: %llu cycles without a bound input\n",
		arflex_component_instance(c), (unsigned long long)t->no_input_cycles);
}

int main(int argc, char **argv)
{
	static struct template t;
	static const struct arflex_component_ops ops = {
		.name = "template",
		.user = &t,
		.configure = template_configure,
		.start = template_start,
		.update = template_update,
		.stop = template_stop,
		.cleanup = template_cleanup,
		.safe = template_safe,
	};

	/* Exit codes: 0 clean, 2 usage, 3 attach, 4 configure, 5 runtime (enum arflex_exit). */
	return arflex_component_main(argc, argv, &ops);
}
