/*
 * test_samples - CTest rt.sample.*: sample-counter and sample-scaler under the rt-core host
 * API, wired together as the DRCR would wire them (counter.count -> scaler.x).
 *
 *   test_samples <case> <sample-counter exe> <sample-scaler exe> <sample-counter.xml> <sample-scaler.xml>
 *   cases: counter, scale, set_param, unbind, safe, nan
 *
 * Ports, parameters (defaults, bounds, mutability) and safe modes come from the bundles'
 * contracts (arflex_host_load_contract, docs/DECISIONS.md D32/D34); this file declares none.
 * Its own choices on a shared machine: a 1 ms period, SCHED_OTHER, no mlockall, no
 * cpu_dma_latency, the heartbeat watchdog off unless a case turns it on, and a case's
 * starting gain.
 *
 * Every case creates its objects under its own runtime id, and ends by checking that no
 * /dev/shm/arflex.<rid>.* or /dev/mqueue/arflex.<rid>.* object and no child process is left.
 * Waits are on conditions with deadlines; nothing asserts on timing.
 */
#define _GNU_SOURCE
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <mqueue.h>
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "arflex/host.h"
#include "arflex/host_contract.h"

#include "sample_type.h"
#include "helper.h" /* rt-core test kit: leak checks */

#define SEC UINT64_C(1000000000)
#define MS UINT64_C(1000000)
#define CALL_TIMEOUT (2 * SEC)
#define WAIT_TIMEOUT (10 * SEC)

static char rid[ARFLEX_ID_MAX + 1];
static const char *counter_exe, *scaler_exe, *counter_xml, *scaler_xml;
static struct arflex_host_contract counter_c, scaler_c;
static struct arflex_host counter_h, scaler_h;
static int failures;

#define CHECK(cond, ...)                                                                   \
	do {                                                                               \
		if (!(cond)) {                                                             \
			fprintf(stderr, "FAIL %s:%d: %s: ", __FILE__, __LINE__, #cond);    \
			fprintf(stderr, __VA_ARGS__);                                      \
			fputc('\n', stderr);                                               \
			failures++;                                                        \
			goto out;                                                          \
		}                                                                          \
	} while (0)

/* Heartbeat timeout of both instances (0: watchdog off); the safe case sets it. While
 * keep_hb is true, every poll writes both runtime heartbeats. */
static uint64_t hb_timeout_ns;
static bool keep_hb;

static const struct arflex_host_type types[] = { ARFLEX_HOST_TYPE(SAMPLE) };

/* The parameter @name of a loaded contract, or NULL. */
static struct arflex_param_slot *param(struct arflex_host_contract *c, const char *name)
{
	for (unsigned i = 0; i < c->nparams; i++)
		if (strcmp(c->params[i].name, name) == 0)
			return &c->params[i];
	return NULL;
}

/* Loads @xml into @c and fills @o from it, with the harness's choices on top. */
static int load(struct arflex_host_contract *c, const char *xml, const char *instance,
		struct arflex_host_opts *o)
{
	char err[512];
	int ret = arflex_host_load_contract(c, xml, types, 1, err, sizeof(err));

	if (ret < 0)
		return fprintf(stderr, "%s\n", err), ret;
	arflex_host_contract_opts(c, rid, instance, o);
	o->config.period_ns = 1 * MS;
	o->config.deadline_ns = 1 * MS;
	o->config.hb_timeout_ns = hb_timeout_ns;
	o->config.priority = 0; /* tests share the machine: SCHED_OTHER */
	o->config.cfg_flags |= ARFLEX_CFG_NO_MLOCK | ARFLEX_CFG_NO_DMA_LATENCY;
	return 0;
}

/* The contract's default amplitude of sample-counter (the bound of its output). */
static double amplitude(void)
{
	struct arflex_param_slot *p = param(&counter_c, "amplitude");

	return p ? arflex_bits_f64(p->default_bits) : NAN;
}

static int make_counter(void)
{
	struct arflex_host_opts o;
	int ret = load(&counter_c, counter_xml, "counter", &o);

	if (ret < 0)
		return ret;
	ret = arflex_host_create(&counter_h, &o);
	if (ret < 0)
		return ret;
	return arflex_host_spawn(&counter_h, counter_exe, NULL, NULL);
}

/* sample-scaler as its contract says, starting with gain @gain (within its bounds). */
static int make_scaler(double gain)
{
	struct arflex_host_opts o;
	struct arflex_param_slot *g;
	int ret = load(&scaler_c, scaler_xml, "scaler", &o);

	if (ret < 0)
		return ret;
	g = param(&scaler_c, "gain");
	if (!g || gain < arflex_bits_f64(g->min_bits) || gain > arflex_bits_f64(g->max_bits))
		return fprintf(stderr, "no gain parameter admitting %g in %s\n", gain, scaler_xml),
		       -EINVAL;
	g->default_bits = arflex_f64_bits(gain);
	ret = arflex_host_create(&scaler_h, &o);
	if (ret < 0)
		return ret;
	return arflex_host_spawn(&scaler_h, scaler_exe, NULL, NULL);
}

/* A reader of one output port of a host, with its own handle (own last_seq). */
struct reader {
	struct arflex_port port;
	struct arflex_sample v;
	uint64_t n; /* new values seen */
};

static int reader_open(struct reader *r, struct arflex_host *h, const char *port)
{
	const char *name = arflex_host_output_name(h, port);

	memset(r, 0, sizeof(*r));
	if (!name)
		return -ENOENT;
	return arflex_port_open(&r->port, name, false, false, ARFLEX_PORT_STATE,
				&sample_port_type);
}

/* 1 if a new value was read into r->v. */
static int reader_poll(struct reader *r)
{
	int ret;

	if (keep_hb) {
		arflex_host_heartbeat(&counter_h);
		arflex_host_heartbeat(&scaler_h);
	}
	ret = arflex_state_read(&r->port, &r->v, sizeof(r->v), NULL);

	if (ret == 1)
		r->n++;
	return ret;
}

/* Ring of recently seen counter samples, to look an input value up by its seq. */
#define HIST 8192
static struct arflex_sample xhist[HIST];

static void xhist_put(const struct arflex_sample *s)
{
	xhist[s->seq % HIST] = *s;
}

static const struct arflex_sample *xhist_get(uint64_t seq)
{
	const struct arflex_sample *s = &xhist[seq % HIST];

	return s->seq == seq ? s : NULL;
}

static bool leaked(void)
{
	/* /dev/mqueue may not be mounted: the kit also probes the tracked queues by name. */
	th_track(rid, "counter");
	th_track(rid, "scaler");
	return th_leftovers(rid) > 0 || !th_no_children();
}

static int start_pair(bool bind)
{
	int ret;

	ret = arflex_host_wait_state(&counter_h, ARFLEX_STATE_READY, WAIT_TIMEOUT);
	if (ret < 0)
		return fprintf(stderr, "counter not READY: %d\n", ret), ret;
	ret = arflex_host_wait_state(&scaler_h, ARFLEX_STATE_READY, WAIT_TIMEOUT);
	if (ret < 0)
		return fprintf(stderr, "scaler not READY: %d\n", ret), ret;
	if (bind) {
		ret = arflex_host_bind(&scaler_h, "x", arflex_host_output_name(&counter_h, "count"),
				       CALL_TIMEOUT);
		if (ret < 0)
			return fprintf(stderr, "BIND scaler.x: %d\n", ret), ret;
	}
	ret = arflex_host_start(&counter_h, CALL_TIMEOUT);
	if (ret < 0)
		return fprintf(stderr, "START counter: %d\n", ret), ret;
	ret = arflex_host_start(&scaler_h, CALL_TIMEOUT);
	if (ret < 0)
		return fprintf(stderr, "START scaler: %d\n", ret), ret;
	return 0;
}

static void dump(void)
{
	fprintf(stderr, "counter state %u, scaler state %u\n",
		counter_h.ctl ? arflex_ctl_state(counter_h.ctl) : 99u,
		scaler_h.ctl ? arflex_ctl_state(scaler_h.ctl) : 99u);
}

/* rt.sample.counter: seq grows, t_ns grows, |value| <= amplitude; an amplitude change shows. */
static int case_counter(void)
{
	struct reader x;
	uint64_t deadline, last_seq = 0, applied = 0;
	int64_t last_t = 0;
	double maxabs = 0.0;
	bool open = false;

	CHECK(make_counter() == 0, "counter create/spawn");
	CHECK(arflex_host_wait_state(&counter_h, ARFLEX_STATE_READY, WAIT_TIMEOUT) == 0, "READY");
	CHECK(reader_open(&x, &counter_h, "count") == 0, "open count");
	open = true;
	CHECK(arflex_host_start(&counter_h, CALL_TIMEOUT) == 0, "START");
	deadline = arflex_sys_now_ns() + WAIT_TIMEOUT;
	while (x.n < 300 && arflex_sys_now_ns() < deadline) {
		if (reader_poll(&x) != 1)
			continue;
		CHECK(x.v.seq > last_seq, "seq %llu after %llu", (unsigned long long)x.v.seq,
		      (unsigned long long)last_seq);
		CHECK(x.v.t_ns > last_t, "t_ns not increasing");
		CHECK(fabs(x.v.value) <= amplitude(), "value %g beyond amplitude %g", x.v.value,
		      amplitude());
		if (fabs(x.v.value) > maxabs)
			maxabs = fabs(x.v.value);
		last_seq = x.v.seq;
		last_t = x.v.t_ns;
	}
	CHECK(x.n >= 300, "only %llu values seen", (unsigned long long)x.n);
	CHECK(maxabs > amplitude() / 4, "the sine does not move (max |value| %g)", maxabs);
	CHECK(arflex_host_set_param(&counter_h, "amplitude", arflex_f64_bits(0.25), &applied,
				    CALL_TIMEOUT) == 0, "SET_PARAM amplitude");
	CHECK(arflex_bits_f64(applied) == 0.25, "applied %g", arflex_bits_f64(applied));
	for (uint64_t n0 = x.n; x.n < n0 + 300 && arflex_sys_now_ns() < deadline;) {
		if (reader_poll(&x) == 1)
			CHECK(fabs(x.v.value) <= 0.25, "value %g beyond new amplitude", x.v.value);
	}
	CHECK(arflex_host_shutdown(&counter_h, CALL_TIMEOUT) == 0, "SHUTDOWN");
	CHECK(arflex_host_wait_exit(&counter_h, WAIT_TIMEOUT) == 0, "exit");
	CHECK(WIFEXITED(arflex_host_exit_status(&counter_h)) &&
	      WEXITSTATUS(arflex_host_exit_status(&counter_h)) == 0, "exit status");
out:
	if (failures)
		dump();
	if (open)
		arflex_port_close(&x.port);
	return 0;
}

/*
 * Polls x and y for @count matched y values (a y whose seq is in the x history) and checks
 * each y.value == gain * x.value exactly, where the gain is @g_old before the switch and
 * @g_new after. @min_new_seq: every y with seq > it must use g_new. Returns the number of
 * matches with each gain through *n_old, *n_new; -1 on a check failure.
 */
static int match_outputs(struct reader *x, struct reader *y, unsigned count, double g_old,
			 double g_new, uint64_t min_new_seq, unsigned *n_old, unsigned *n_new)
{
	uint64_t deadline = arflex_sys_now_ns() + WAIT_TIMEOUT;
	unsigned matched = 0;
	bool seen_new = false;

	*n_old = *n_new = 0;
	while (matched < count && arflex_sys_now_ns() < deadline) {
		const struct arflex_sample *in;
		bool is_new, is_old;

		if (reader_poll(x) == 1)
			xhist_put(&x->v);
		if (reader_poll(y) != 1)
			continue;
		in = xhist_get(y->v.seq);
		if (!in)
			continue;
		matched++;
		if (y->v.t_ns != in->t_ns) {
			fprintf(stderr, "FAIL: y seq %llu t_ns %lld, x t_ns %lld\n",
				(unsigned long long)y->v.seq, (long long)y->v.t_ns,
				(long long)in->t_ns);
			return -1;
		}
		is_new = y->v.value == g_new * in->value;
		is_old = y->v.value == g_old * in->value;
		if (is_new && is_old) {
			(*n_new)++; /* x == 0 or equal gains: either gain gives this */
		} else if (is_new) {
			seen_new = true;
			(*n_new)++;
		} else if (is_old && (seen_new || y->v.seq > min_new_seq)) {
			fprintf(stderr, "FAIL: y seq %llu still uses the old gain %g (%s)\n",
				(unsigned long long)y->v.seq, g_old,
				seen_new ? "after a new-gain output" : "input newer than the reply");
			return -1;
		} else if (is_old) {
			(*n_old)++;
		} else {
			fprintf(stderr, "FAIL: y seq %llu = %.17g, x = %.17g, gain %g/%g\n",
				(unsigned long long)y->v.seq, y->v.value, in->value, g_old, g_new);
			return -1;
		}
	}
	if (matched < count) {
		fprintf(stderr, "FAIL: only %u of %u outputs matched an input\n", matched, count);
		return -1;
	}
	return 0;
}

/* rt.sample.scale: y == gain * x for matching seq, y carries x's seq and t_ns. */
static int case_scale(void)
{
	struct reader x, y;
	unsigned n_old, n_new;
	int nopen = 0;

	CHECK(make_counter() == 0, "counter create/spawn");
	CHECK(make_scaler(1.5) == 0, "scaler create/spawn");
	CHECK(reader_open(&x, &counter_h, "count") == 0, "open count");
	nopen++;
	CHECK(reader_open(&y, &scaler_h, "y") == 0, "open y");
	nopen++;
	CHECK(start_pair(true) == 0, "start");
	CHECK(match_outputs(&x, &y, 200, 1.5, 1.5, UINT64_MAX, &n_old, &n_new) == 0, "match");
	CHECK(n_new == 200, "%u matches with gain 1.5", n_new);
	CHECK(arflex_host_shutdown(&scaler_h, CALL_TIMEOUT) == 0, "SHUTDOWN scaler");
	CHECK(arflex_host_shutdown(&counter_h, CALL_TIMEOUT) == 0, "SHUTDOWN counter");
out:
	if (failures)
		dump();
	if (nopen > 1)
		arflex_port_close(&y.port);
	if (nopen > 0)
		arflex_port_close(&x.port);
	return 0;
}

/* rt.sample.set_param: a gain change while running is applied at a cycle boundary: read back
 * through SET_PARAM's reply and GET_PARAM, every output after the reply uses the new gain,
 * and no output after the first new-gain one uses the old gain. */
static int case_set_param(void)
{
	struct reader x, y;
	unsigned n_old, n_new;
	uint64_t applied = 0, got = 0, x_seq_after;
	int nopen = 0;

	CHECK(make_counter() == 0, "counter create/spawn");
	CHECK(make_scaler(2.0) == 0, "scaler create/spawn");
	CHECK(reader_open(&x, &counter_h, "count") == 0, "open count");
	nopen++;
	CHECK(reader_open(&y, &scaler_h, "y") == 0, "open y");
	nopen++;
	CHECK(start_pair(true) == 0, "start");
	CHECK(match_outputs(&x, &y, 50, 2.0, 2.0, UINT64_MAX, &n_old, &n_new) == 0, "before");
	CHECK(arflex_host_set_param(&scaler_h, "gain", arflex_f64_bits(-3.25), &applied,
				    CALL_TIMEOUT) == 0, "SET_PARAM gain");
	CHECK(arflex_bits_f64(applied) == -3.25, "applied %g", arflex_bits_f64(applied));
	/* Every x written from now on can only be scaled with the new gain. */
	x_seq_after = 0;
	{
		uint64_t dl = arflex_sys_now_ns() + WAIT_TIMEOUT;

		while (x_seq_after == 0 && arflex_sys_now_ns() < dl)
			if (reader_poll(&x) == 1) {
				xhist_put(&x.v);
				x_seq_after = x.v.seq;
			}
	}
	CHECK(x_seq_after > 0, "no counter value after SET_PARAM");
	CHECK(match_outputs(&x, &y, 100, 2.0, -3.25, x_seq_after, &n_old, &n_new) == 0, "after");
	CHECK(n_new >= 90, "only %u of 100 outputs with the new gain", n_new);
	CHECK(arflex_host_get_param(&scaler_h, "gain", &got, CALL_TIMEOUT) == 0, "GET_PARAM");
	CHECK(arflex_bits_f64(got) == -3.25, "GET_PARAM gain %g", arflex_bits_f64(got));
	/* Out of range is refused and changes nothing. */
	CHECK(arflex_host_set_param(&scaler_h, "gain", arflex_f64_bits(50.0), NULL,
				    CALL_TIMEOUT) == -ERANGE, "gain 50 accepted");
	CHECK(arflex_host_get_param(&scaler_h, "gain", &got, CALL_TIMEOUT) == 0, "GET_PARAM");
	CHECK(arflex_bits_f64(got) == -3.25, "gain %g after a refused change",
	      arflex_bits_f64(got));
	CHECK(arflex_host_shutdown(&scaler_h, CALL_TIMEOUT) == 0, "SHUTDOWN scaler");
	CHECK(arflex_host_shutdown(&counter_h, CALL_TIMEOUT) == 0, "SHUTDOWN counter");
out:
	if (failures)
		dump();
	if (nopen > 1)
		arflex_port_close(&y.port);
	if (nopen > 0)
		arflex_port_close(&x.port);
	return 0;
}

/* rt.sample.unbind: after UNBIND of scaler.x, y gets one zero sample (safe mode "zero") and
 * then stops changing while the counter goes on; a new BIND resumes scaling. */
static int case_unbind(void)
{
	struct reader x, y;
	unsigned n_old, n_new;
	uint64_t deadline, x_seen;
	int nopen = 0;

	CHECK(make_counter() == 0, "counter create/spawn");
	CHECK(make_scaler(0.5) == 0, "scaler create/spawn");
	CHECK(reader_open(&x, &counter_h, "count") == 0, "open count");
	nopen++;
	CHECK(reader_open(&y, &scaler_h, "y") == 0, "open y");
	nopen++;
	CHECK(start_pair(true) == 0, "start");
	CHECK(match_outputs(&x, &y, 50, 0.5, 0.5, UINT64_MAX, &n_old, &n_new) == 0, "bound");
	CHECK(arflex_host_unbind(&scaler_h, "x", CALL_TIMEOUT) == 0, "UNBIND");
	CHECK(arflex_host_unbind(&scaler_h, "x", CALL_TIMEOUT) == -ENOTCONN,
	      "second UNBIND not -ENOTCONN");
	/* Drain until the zero sample shows up. */
	deadline = arflex_sys_now_ns() + WAIT_TIMEOUT;
	while (!(y.v.value == 0.0 && y.n > 0) && arflex_sys_now_ns() < deadline)
		reader_poll(&y);
	CHECK(y.v.value == 0.0, "no zero output after UNBIND (last %g)", y.v.value);
	/* The counter goes on for 100 more samples; y must not change any more. */
	x_seen = 0;
	deadline = arflex_sys_now_ns() + WAIT_TIMEOUT;
	while (x_seen < 100 && arflex_sys_now_ns() < deadline) {
		if (reader_poll(&x) == 1)
			x_seen++;
		CHECK(reader_poll(&y) == 0, "y changed after UNBIND: seq %llu value %g",
		      (unsigned long long)y.v.seq, y.v.value);
	}
	CHECK(x_seen == 100, "counter stalled (%llu)", (unsigned long long)x_seen);
	/* Bind again: scaling resumes. */
	CHECK(arflex_host_bind(&scaler_h, "x", arflex_host_output_name(&counter_h, "count"),
			       CALL_TIMEOUT) == 0, "re-BIND");
	CHECK(match_outputs(&x, &y, 50, 0.5, 0.5, UINT64_MAX, &n_old, &n_new) == 0, "rebound");
	CHECK(arflex_host_shutdown(&scaler_h, CALL_TIMEOUT) == 0, "SHUTDOWN scaler");
	CHECK(arflex_host_shutdown(&counter_h, CALL_TIMEOUT) == 0, "SHUTDOWN counter");
out:
	if (failures)
		dump();
	if (nopen > 1)
		arflex_port_close(&y.port);
	if (nopen > 0)
		arflex_port_close(&x.port);
	return 0;
}

static bool safe_active(struct arflex_host *h)
{
	return arflex_ctl_flags(h->ctl) & ARFLEX_FLAG_SAFE_ACTIVE;
}

/* rt.sample.safe: when the runtime heartbeat stops, the counter holds (count stops changing)
 * and the scaler drives y to zero every cycle (their contracts' safe modes); when it comes
 * back both leave safe mode by themselves (they do not move hardware) and scaling resumes. */
static int case_safe(void)
{
	struct reader x, y;
	unsigned n_old, n_new;
	uint64_t deadline, zeros;
	int nopen = 0;

	hb_timeout_ns = 150 * MS;
	keep_hb = true;
	CHECK(make_counter() == 0, "counter create/spawn");
	CHECK(make_scaler(2.5) == 0, "scaler create/spawn");
	CHECK(reader_open(&x, &counter_h, "count") == 0, "open count");
	nopen++;
	CHECK(reader_open(&y, &scaler_h, "y") == 0, "open y");
	nopen++;
	CHECK(start_pair(true) == 0, "start");
	CHECK(match_outputs(&x, &y, 50, 2.5, 2.5, UINT64_MAX, &n_old, &n_new) == 0, "live");
	CHECK(!safe_active(&counter_h) && !safe_active(&scaler_h), "safe mode while heartbeating");
	/* The runtime goes silent. */
	keep_hb = false;
	deadline = arflex_sys_now_ns() + WAIT_TIMEOUT;
	while (!(safe_active(&counter_h) && safe_active(&scaler_h)) &&
	       arflex_sys_now_ns() < deadline)
		reader_poll(&y);
	CHECK(safe_active(&counter_h) && safe_active(&scaler_h), "no safe mode without heartbeat");
	reader_poll(&x); /* the counter's last value before safe mode */
	/* 50 new y values, all zero; meanwhile no new count value (hold). */
	zeros = 0;
	deadline = arflex_sys_now_ns() + WAIT_TIMEOUT;
	while (zeros < 50 && arflex_sys_now_ns() < deadline) {
		CHECK(reader_poll(&x) == 0, "count changed in safe mode (hold): seq %llu",
		      (unsigned long long)x.v.seq);
		if (reader_poll(&y) == 1) {
			CHECK(y.v.value == 0.0, "y = %g in safe mode (zero)", y.v.value);
			zeros++;
		}
	}
	CHECK(zeros == 50, "only %llu zero outputs in safe mode", (unsigned long long)zeros);
	CHECK(scaler_h.ctl->warnings[ARFLEX_WARN_SAFE] >= 1, "safe warning not counted");
	/* The runtime is back: safe mode ends by itself, scaling resumes. */
	keep_hb = true;
	deadline = arflex_sys_now_ns() + WAIT_TIMEOUT;
	while ((safe_active(&counter_h) || safe_active(&scaler_h)) &&
	       arflex_sys_now_ns() < deadline)
		reader_poll(&y);
	CHECK(!safe_active(&counter_h) && !safe_active(&scaler_h), "safe mode did not end");
	CHECK(match_outputs(&x, &y, 50, 2.5, 2.5, UINT64_MAX, &n_old, &n_new) == 0, "resumed");
	CHECK(arflex_host_shutdown(&scaler_h, CALL_TIMEOUT) == 0, "SHUTDOWN scaler");
	CHECK(arflex_host_shutdown(&counter_h, CALL_TIMEOUT) == 0, "SHUTDOWN counter");
out:
	if (failures)
		dump();
	if (nopen > 1)
		arflex_port_close(&y.port);
	if (nopen > 0)
		arflex_port_close(&x.port);
	return 0;
}

static uint64_t update_errors(struct arflex_host *h)
{
	struct arflex_stats st;

	while (arflex_ctl_stats_read(h->ctl, &st) != 0)
		; /* the RT thread is updating the block: read again */
	return st.update_errors;
}

/* Writes @n values into the counter's count segment through @w; true when the scaler's
 * update_errors grew past @errs meanwhile (it took at least one), *@y_bad set when y showed a
 * non-finite value. */
static bool inject(struct arflex_port *w, struct reader *y, double value, unsigned n,
		   uint64_t errs, bool *y_bad)
{
	uint64_t deadline = arflex_sys_now_ns() + WAIT_TIMEOUT;
	struct arflex_sample s = { .seq = 1u << 30, .value = value };

	for (unsigned i = 0; i < n && arflex_sys_now_ns() < deadline; i++) {
		s.seq++;
		s.t_ns = (int64_t)arflex_sys_now_ns();
		arflex_state_write(w, &s, sizeof(s));
		/* wait for the scaler to take it: an error counted, then 2 ms for y */
		while (update_errors(&scaler_h) <= errs + i && arflex_sys_now_ns() < deadline)
			if (reader_poll(y) == 1 && !isfinite(y->v.value))
				*y_bad = true;
	}
	return update_errors(&scaler_h) > errs;
}

/* rt.sample.nan: NaN and infinity written into counter.count (the counter stopped) are not
 * used by the scaler: y never carries them and holds its last value, every bad input counts
 * an update error; a valid value after them is scaled again, an overwritten segment header
 * is counted in ARFLEX_WARN_INPUT, and after all that the counter's flow is scaled again. */
static int case_nan(void)
{
	struct reader x, y;
	struct arflex_port w;
	unsigned n_old, n_new;
	uint64_t errs, held_seq, deadline;
	bool y_bad = false, stopped = false;
	int nopen = 0;

	CHECK(make_counter() == 0, "counter create/spawn");
	CHECK(make_scaler(1.5) == 0, "scaler create/spawn");
	CHECK(reader_open(&x, &counter_h, "count") == 0, "open count");
	nopen++;
	CHECK(reader_open(&y, &scaler_h, "y") == 0, "open y");
	nopen++;
	CHECK(start_pair(true) == 0, "start");
	CHECK(match_outputs(&x, &y, 50, 1.5, 1.5, UINT64_MAX, &n_old, &n_new) == 0, "before");
	/* The counter stops writing; the test writes its segment instead. */
	CHECK(kill(counter_h.pid, SIGSTOP) == 0, "SIGSTOP counter");
	stopped = true;
	CHECK(arflex_port_open(&w, arflex_host_output_name(&counter_h, "count"), true, true,
			       ARFLEX_PORT_STATE, &sample_port_type) == 0, "open count for writing");
	nopen++;
	/* The counter may have stopped between completing a slot and publishing head: skip one
	 * index so that no value of ours carries the seq the scaler read last. */
	w.next_idx++;
	deadline = arflex_sys_now_ns() + 20 * MS;
	while (arflex_sys_now_ns() < deadline)
		reader_poll(&y); /* drain: y's last value before the bad input */
	held_seq = y.v.seq;
	errs = update_errors(&scaler_h);
	CHECK(inject(&w, &y, NAN, 20, errs, &y_bad), "NaN: no update error counted (%llu)",
	      (unsigned long long)update_errors(&scaler_h));
	CHECK(inject(&w, &y, INFINITY, 5, errs + 20, &y_bad), "Inf: no update error counted");
	CHECK(update_errors(&scaler_h) >= errs + 25, "%llu update errors for 25 bad values",
	      (unsigned long long)(update_errors(&scaler_h) - errs));
	CHECK(!y_bad, "y carried a non-finite value");
	CHECK(y.v.seq == held_seq && isfinite(y.v.value), "y did not hold: seq %llu value %g",
	      (unsigned long long)y.v.seq, y.v.value);
	/* A valid value flows again. */
	{
		struct arflex_sample s = { .seq = 7u << 30, .value = 2.0 };

		s.t_ns = (int64_t)arflex_sys_now_ns();
		CHECK(arflex_state_write(&w, &s, sizeof(s)) == 0, "write 2.0");
		deadline = arflex_sys_now_ns() + WAIT_TIMEOUT;
		while (y.v.seq != s.seq && arflex_sys_now_ns() < deadline)
			reader_poll(&y);
		CHECK(y.v.seq == s.seq && y.v.value == 3.0, "y after a valid value: seq %llu %g",
		      (unsigned long long)y.v.seq, y.v.value);
		/* An overwritten header is noticed by the read (ARFLEX_WARN_INPUT); restored, the
		 * next value flows. */
		w.hdr->magic ^= 1;
		deadline = arflex_sys_now_ns() + WAIT_TIMEOUT;
		while (__atomic_load_n(&scaler_h.ctl->warnings[ARFLEX_WARN_INPUT], __ATOMIC_RELAXED) == 0 &&
		       arflex_sys_now_ns() < deadline)
			;
		w.hdr->magic ^= 1;
		CHECK(scaler_h.ctl->warnings[ARFLEX_WARN_INPUT] > 0, "damaged header not counted");
		s.seq++;
		s.value = -2.0;
		CHECK(arflex_state_write(&w, &s, sizeof(s)) == 0, "write -2.0");
		while (y.v.seq != s.seq && arflex_sys_now_ns() < deadline)
			reader_poll(&y);
		CHECK(y.v.seq == s.seq && y.v.value == -3.0, "y after the header was restored: %g",
		      y.v.value);
	}
	arflex_port_close(&w);
	nopen--;
	CHECK(kill(counter_h.pid, SIGCONT) == 0, "SIGCONT counter");
	stopped = false;
	CHECK(match_outputs(&x, &y, 50, 1.5, 1.5, UINT64_MAX, &n_old, &n_new) == 0, "after");
	CHECK(arflex_host_shutdown(&scaler_h, CALL_TIMEOUT) == 0, "SHUTDOWN scaler");
	CHECK(arflex_host_shutdown(&counter_h, CALL_TIMEOUT) == 0, "SHUTDOWN counter");
out:
	if (failures)
		dump();
	if (stopped)
		kill(counter_h.pid, SIGCONT);
	if (nopen > 2)
		arflex_port_close(&w);
	if (nopen > 1)
		arflex_port_close(&y.port);
	if (nopen > 0)
		arflex_port_close(&x.port);
	return 0;
}

int main(int argc, char **argv)
{
	static const struct {
		const char *name;
		int (*fn)(void);
	} cases[] = {
		{ "counter", case_counter },
		{ "scale", case_scale },
		{ "set_param", case_set_param },
		{ "unbind", case_unbind },
		{ "safe", case_safe },
		{ "nan", case_nan },
	};
	int (*fn)(void) = NULL;

	if (argc != 6) {
		fprintf(stderr, "usage: %s counter|scale|set_param|unbind|safe|nan <sample-counter> "
			"<sample-scaler> <sample-counter.xml> <sample-scaler.xml>\n", argv[0]);
		return 2;
	}
	for (unsigned i = 0; i < sizeof(cases) / sizeof(cases[0]); i++)
		if (strcmp(argv[1], cases[i].name) == 0)
			fn = cases[i].fn;
	if (!fn) {
		fprintf(stderr, "test_samples: unknown case '%s'\n", argv[1]);
		return 2;
	}
	counter_exe = argv[2];
	scaler_exe = argv[3];
	counter_xml = argv[4];
	scaler_xml = argv[5];
	snprintf(rid, sizeof(rid), "t-sample-%ld", (long)getpid());
	fn();
	arflex_host_destroy(&scaler_h);
	arflex_host_destroy(&counter_h);
	if (leaked()) {
		fprintf(stderr, "FAIL: objects or children leaked\n");
		failures++;
	}
	if (failures) {
		fprintf(stderr, "rt.sample.%s: %d failure(s)\n", argv[1], failures);
		return 1;
	}
	printf("rt.sample.%s: ok\n", argv[1]);
	return 0;
}
