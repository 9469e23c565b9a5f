/*
 * test_debug_monitor - CTest debugmon.*: the debug-monitor RT half under the rt-core host API,
 * bound to synthetic providers this test creates and writes itself (so every observed value
 * is known exactly).
 *
 *   test_debug_monitor <case> <debug-monitor exe> <debug-monitor.xml> <native/tests dir>
 *
 * The monitor's ports, parameter and safe mode come from a contract (arflex_host_load_contract,
 * docs/DECISIONS.md D32/D34): rebind runs the bundle's own; mirror and noslot run the watcher
 * contracts in native/tests/ (mirror.xml: slot 1 with its last value only; noslot.xml: no
 * m<k>_last output), as a user writes one (README). Nothing is declared in this file. The
 * harness's own choices: a 2 ms period, SCHED_OTHER, no mlock, no cpu_dma_latency, no
 * heartbeat watchdog, and the case's window.
 *   cases:
 *     mirror   m0_last mirrors the provider verbatim; min/max/mean per window of 4 values;
 *              the provider's segment is never written by the monitor (consumer half of its
 *              header stays zero); a slot without stats ports (m1) works with last only
 *     rebind   unbind holds the outputs and drops the partial window; rebinding to another
 *              provider resumes; a window change at run time takes effect
 *     noslot   a contract with no m<k>_last port: configure fails, state FAILED, clear message
 *
 * Every case creates its objects under its own runtime id and ends by checking that no
 * /dev/shm/arflex.<rid>.* or /dev/mqueue/arflex.<rid>.* object and no child is left. Waits are
 * on conditions with deadlines; nothing asserts on timing.
 */
#define _GNU_SOURCE
#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "arflex/host.h"
#include "arflex/host_contract.h"
#include "arflex_types/sample.h"
#include "helper.h" /* rt-core test kit: leak checks */

#define SEC UINT64_C(1000000000)
#define MS UINT64_C(1000000)
#define CALL_TIMEOUT (2 * SEC)
#define WAIT_TIMEOUT (10 * SEC)

static const struct arflex_port_type sample_type = {
	.name = ARFLEX_TYPE_SAMPLE_NAME,
	.major = ARFLEX_TYPE_SAMPLE_VERSION_MAJOR,
	.minor = ARFLEX_TYPE_SAMPLE_VERSION_MINOR,
	.elem_size = ARFLEX_TYPE_SAMPLE_SIZE,
};

static char rid[ARFLEX_ID_MAX + 1];
static const char *mon_exe, *bundle_xml, *tests_dir;
static struct arflex_host mon;
static struct arflex_port src[2];    /* synthetic providers */
static char src_name[2][ARFLEX_OBJ_NAME_SIZE];
static bool src_made[2];
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

static int make_src(unsigned i)
{
	struct arflex_port_spec spec = { .method = ARFLEX_PORT_STATE, .type = sample_type,
					 .depth = 1 };
	char inst[32];
	int ret;

	snprintf(inst, sizeof(inst), "src%u", i);
	snprintf(src_name[i], sizeof(src_name[i]), "/arflex.%s.%s.out.v", rid, inst);
	ret = arflex_port_create(&src[i], src_name[i], &spec);
	if (ret == 0)
		src_made[i] = true;
	return ret;
}

/* The monitor as the contract @xml (a path, or a file name under tests_dir) declares it, its
 * window starting at @window. */
static int make_monitor(const char *xml, int64_t window)
{
	static const struct arflex_host_type types[] = { ARFLEX_HOST_TYPE(SAMPLE) };
	static struct arflex_host_contract c;
	struct arflex_host_opts o;
	char path[512], err[512];
	int ret;

	if (strchr(xml, '/'))
		snprintf(path, sizeof(path), "%s", xml);
	else
		snprintf(path, sizeof(path), "%s/%s", tests_dir, xml);
	ret = arflex_host_load_contract(&c, path, types, 1, err, sizeof(err));
	if (ret < 0)
		return fprintf(stderr, "%s\n", err), ret;
	if (c.nparams != 1 || strcmp(c.params[0].name, "window") != 0 ||
	    window < (int64_t)c.params[0].min_bits || window > (int64_t)c.params[0].max_bits)
		return fprintf(stderr, "%s: no window parameter admitting %lld\n", path,
			       (long long)window), -EINVAL;
	c.params[0].default_bits = (uint64_t)window;
	arflex_host_contract_opts(&c, rid, "debug-monitor", &o);
	o.config.period_ns = 2 * MS;
	o.config.deadline_ns = 2 * MS;
	o.config.priority = 0; /* tests share the machine: SCHED_OTHER */
	o.config.hb_timeout_ns = 0;
	o.config.cfg_flags |= ARFLEX_CFG_NO_MLOCK | ARFLEX_CFG_NO_DMA_LATENCY;
	ret = arflex_host_create(&mon, &o);
	if (ret < 0)
		return ret;
	return arflex_host_spawn(&mon, mon_exe, NULL, NULL);
}

/* A reader of one monitor output with its own last-seq. */
struct reader {
	struct arflex_port port;
	bool open;
	struct arflex_sample v;
};

static int reader_open(struct reader *r, const char *port)
{
	const char *name = arflex_host_output_name(&mon, port);
	int ret;

	memset(r, 0, sizeof(*r));
	if (!name)
		return -ENOENT;
	ret = arflex_port_open(&r->port, name, false, false, ARFLEX_PORT_STATE, &sample_type);
	r->open = ret == 0;
	return ret;
}

static void reader_close(struct reader *r)
{
	if (r->open)
		arflex_port_close(&r->port);
	r->open = false;
}

/* Waits until the reader shows a value whose seq is @seq; 0 or -ETIMEDOUT. */
static int wait_seq(struct reader *r, uint64_t seq)
{
	uint64_t deadline = arflex_sys_now_ns() + WAIT_TIMEOUT;

	while (arflex_sys_now_ns() < deadline) {
		struct arflex_sample s;

		if (arflex_state_read(&r->port, &s, sizeof(s), NULL) == 1)
			r->v = s;
		if (r->v.seq == seq)
			return 0;
		usleep(200); /* poll interval of a condition with a deadline */
	}
	return -ETIMEDOUT;
}

static uint64_t mon_cycles(void)
{
	struct arflex_stats st;

	if (arflex_ctl_stats_read(mon.ctl, &st) < 0)
		return 0;
	return st.cycles;
}

/* Waits until the monitor has run at least @n more cycles; 0 or -ETIMEDOUT. */
static int wait_cycles(uint64_t n)
{
	uint64_t until = mon_cycles() + n, deadline = arflex_sys_now_ns() + WAIT_TIMEOUT;

	while (arflex_sys_now_ns() < deadline) {
		if (mon_cycles() >= until)
			return 0;
		usleep(200);
	}
	return -ETIMEDOUT;
}

/* Sample seqs of the two providers never overlap, so a mirrored sample names its source. */
static uint64_t next_seq[2] = { 0, 1000000 };

static void src_write(unsigned i, double value)
{
	struct arflex_sample s = { .seq = ++next_seq[i], .t_ns = (int64_t)arflex_sys_now_ns(),
				   .value = value };

	arflex_state_write(&src[i], &s, sizeof(s));
}

/* True when the consumer half of a provider's header (offsets 192..255) is all zero. */
static bool consumer_half_untouched(unsigned i)
{
	const unsigned char *h = src[i].base;

	for (unsigned k = 192; k < 256; k++)
		if (h[k])
			return false;
	return true;
}

static bool leaked(void)
{
	return th_leftovers(rid) > 0 || !th_no_children();
}

static int start_monitor(void)
{
	int ret = arflex_host_wait_state(&mon, ARFLEX_STATE_READY, WAIT_TIMEOUT);

	if (ret < 0)
		return fprintf(stderr, "monitor not READY: %d\n", ret), ret;
	ret = arflex_host_bind(&mon, "m0", src_name[0], CALL_TIMEOUT);
	if (ret < 0)
		return fprintf(stderr, "BIND m0: %d\n", ret), ret;
	ret = arflex_host_bind(&mon, "m1", src_name[1], CALL_TIMEOUT);
	if (ret < 0)
		return fprintf(stderr, "BIND m1: %d\n", ret), ret;
	ret = arflex_host_start(&mon, CALL_TIMEOUT);
	if (ret < 0)
		return fprintf(stderr, "START: %d\n", ret), ret;
	return 0;
}

/* Writes @v to provider 0 and waits until m0_last mirrors it exactly. */
static int feed(struct reader *last, double v)
{
	src_write(0, v);
	if (wait_seq(last, next_seq[0]) < 0) {
		fprintf(stderr, "m0_last never showed seq %llu (value %g)\n",
			(unsigned long long)next_seq[0], v);
		return -1;
	}
	if (last->v.value != v) {
		fprintf(stderr, "m0_last seq %llu = %g, provider wrote %g\n",
			(unsigned long long)last->v.seq, last->v.value, v);
		return -1;
	}
	return 0;
}

/* debugmon.mirror */
static int case_mirror(void)
{
	static const double w1[4] = { 3.0, -1.0, 5.0, 1.0 }, w2[4] = { 0.5, 0.25, 0.75, 2.5 };
	struct reader last, mn, mx, mean, last1;
	int64_t t_last;

	memset(&last, 0, sizeof(last));
	memset(&mn, 0, sizeof(mn));
	memset(&mx, 0, sizeof(mx));
	memset(&mean, 0, sizeof(mean));
	memset(&last1, 0, sizeof(last1));
	CHECK(make_src(0) == 0 && make_src(1) == 0, "create providers");
	CHECK(make_monitor("mirror.xml", 4) == 0, "monitor create/spawn");
	CHECK(start_monitor() == 0, "start");
	CHECK(reader_open(&last, "m0_last") == 0, "open m0_last");
	CHECK(reader_open(&mn, "m0_min") == 0, "open m0_min");
	CHECK(reader_open(&mx, "m0_max") == 0, "open m0_max");
	CHECK(reader_open(&mean, "m0_mean") == 0, "open m0_mean");
	CHECK(reader_open(&last1, "m1_last") == 0, "open m1_last");
	for (unsigned i = 0; i < 4; i++)
		CHECK(feed(&last, w1[i]) == 0, "window 1 value %u", i);
	t_last = last.v.t_ns;
	CHECK(wait_seq(&mn, 1) == 0, "m0_min of window 1");
	CHECK(wait_seq(&mx, 1) == 0, "m0_max of window 1");
	CHECK(wait_seq(&mean, 1) == 0, "m0_mean of window 1");
	CHECK(mn.v.value == -1.0 && mx.v.value == 5.0 && mean.v.value == 2.0,
	      "window 1: min %g max %g mean %g (want -1 5 2)", mn.v.value, mx.v.value,
	      mean.v.value);
	CHECK(mn.v.t_ns == t_last, "window t_ns is the last value's");
	for (unsigned i = 0; i < 4; i++)
		CHECK(feed(&last, w2[i]) == 0, "window 2 value %u", i);
	CHECK(wait_seq(&mn, 2) == 0 && wait_seq(&mx, 2) == 0 && wait_seq(&mean, 2) == 0,
	      "window 2 published");
	CHECK(mn.v.value == 0.25 && mx.v.value == 2.5 && mean.v.value == 1.0,
	      "window 2: min %g max %g mean %g (want 0.25 2.5 1)", mn.v.value, mx.v.value,
	      mean.v.value);
	/* slot 1 has only its last port */
	src_write(1, 42.0);
	CHECK(wait_seq(&last1, next_seq[1]) == 0, "m1_last mirrors provider 1");
	CHECK(last1.v.value == 42.0, "m1_last %g", last1.v.value);
	CHECK(consumer_half_untouched(0) && consumer_half_untouched(1),
	      "the monitor wrote a provider's segment");
	CHECK(arflex_host_shutdown(&mon, CALL_TIMEOUT) == 0, "SHUTDOWN");
	CHECK(arflex_host_wait_exit(&mon, WAIT_TIMEOUT) == 0, "exit");
	CHECK(WIFEXITED(arflex_host_exit_status(&mon)) &&
	      WEXITSTATUS(arflex_host_exit_status(&mon)) == 0, "exit status");
out:
	reader_close(&last);
	reader_close(&mn);
	reader_close(&mx);
	reader_close(&mean);
	reader_close(&last1);
	return 0;
}

/* debugmon.rebind */
static int case_rebind(void)
{
	struct reader last, mean;
	uint64_t applied = 0;

	memset(&last, 0, sizeof(last));
	memset(&mean, 0, sizeof(mean));
	CHECK(make_src(0) == 0 && make_src(1) == 0, "create providers");
	CHECK(make_monitor(bundle_xml, 2) == 0, "monitor create/spawn");
	CHECK(start_monitor() == 0, "start");
	CHECK(reader_open(&last, "m0_last") == 0, "open m0_last");
	CHECK(reader_open(&mean, "m0_mean") == 0, "open m0_mean");
	CHECK(feed(&last, 10.0) == 0, "first value");
	/* partial window (1 of 2), then the provider goes away: outputs hold */
	CHECK(arflex_host_unbind(&mon, "m0", CALL_TIMEOUT) == 0, "UNBIND m0");
	CHECK(wait_cycles(2) == 0, "cycles after UNBIND"); /* picked up at a cycle boundary */
	src_write(0, 99.0); /* not observed: unbound */
	CHECK(wait_cycles(20) == 0, "monitor keeps cycling while unbound");
	{
		struct arflex_sample s;
		int r = arflex_state_read(&last.port, &s, sizeof(s), NULL);

		CHECK(r == 0, "m0_last changed while unbound (read %d, seq %llu)", r,
		      (unsigned long long)s.seq);
	}
	CHECK(mean.v.seq == 0 && arflex_state_read(&mean.port, &mean.v, sizeof(mean.v), NULL) == 0,
	      "a window was published from a partial one");
	/* rebind m0 to provider 1 (another source): the partial window was dropped, so the
	 * first window is exactly the next two values of provider 1 */
	CHECK(arflex_host_bind(&mon, "m0", src_name[1], CALL_TIMEOUT) == 0, "BIND m0 -> src1");
	src_write(1, 4.0);
	CHECK(wait_seq(&last, next_seq[1]) == 0 && last.v.value == 4.0, "m0_last follows src1");
	src_write(1, 8.0);
	CHECK(wait_seq(&last, next_seq[1]) == 0 && last.v.value == 8.0, "m0_last follows src1");
	CHECK(wait_seq(&mean, 1) == 0, "first window after rebind");
	CHECK(mean.v.value == 6.0, "mean %g, want 6 (the value seen before unbind must not count)",
	      mean.v.value);
	/* window 2 -> 3 at run time */
	CHECK(arflex_host_set_param(&mon, "window", 3, &applied, CALL_TIMEOUT) == 0,
	      "SET_PARAM window");
	CHECK(applied == 3, "applied window %llu", (unsigned long long)applied);
	CHECK(wait_cycles(3) == 0, "cycles after SET_PARAM");
	for (unsigned i = 1; i <= 3; i++) {
		src_write(1, (double)i);
		CHECK(wait_seq(&last, next_seq[1]) == 0, "value %u of a 3-window", i);
		if (i < 3) {
			struct arflex_sample s;

			CHECK(arflex_state_read(&mean.port, &s, sizeof(s), NULL) == 0,
			      "window published after %u of 3 values", i);
		}
	}
	CHECK(wait_seq(&mean, 2) == 0, "3-window published");
	CHECK(mean.v.value == 2.0, "mean of 1,2,3 = %g", mean.v.value);
	CHECK(arflex_host_shutdown(&mon, CALL_TIMEOUT) == 0, "SHUTDOWN");
	CHECK(arflex_host_wait_exit(&mon, WAIT_TIMEOUT) == 0, "exit");
out:
	reader_close(&last);
	reader_close(&mean);
	return 0;
}

/* debugmon.noslot */
static int case_noslot(void)
{
	int st;

	CHECK(make_monitor("noslot.xml", 4) == 0, "monitor create/spawn");
	CHECK(arflex_host_wait_exit(&mon, WAIT_TIMEOUT) == 0, "the monitor exits");
	st = arflex_host_exit_status(&mon);
	CHECK(WIFEXITED(st) && WEXITSTATUS(st) == ARFLEX_EXIT_CONFIGURE, "exit status %d", st);
	CHECK(arflex_ctl_state(mon.ctl) == ARFLEX_STATE_FAILED, "state %u",
	      arflex_ctl_state(mon.ctl));
	CHECK(mon.ctl->exit_status == -EINVAL, "ctl exit_status %d", mon.ctl->exit_status);
out:
	return 0;
}

int main(int argc, char **argv)
{
	static const struct {
		const char *name;
		int (*fn)(void);
	} cases[] = {
		{ "mirror", case_mirror },
		{ "rebind", case_rebind },
		{ "noslot", case_noslot },
	};
	int (*fn)(void) = NULL;

	if (argc != 5) {
		fprintf(stderr, "usage: %s mirror|rebind|noslot <debug-monitor> <debug-monitor.xml> "
			"<native/tests dir>\n", argv[0]);
		return 2;
	}
	for (unsigned i = 0; i < sizeof(cases) / sizeof(cases[0]); i++)
		if (strcmp(argv[1], cases[i].name) == 0)
			fn = cases[i].fn;
	if (!fn) {
		fprintf(stderr, "test_debug_monitor: unknown case '%s'\n", argv[1]);
		return 2;
	}
	mon_exe = argv[2];
	bundle_xml = argv[3];
	tests_dir = argv[4];
	snprintf(rid, sizeof(rid), "t-debugmon-%ld", (long)getpid());
	fn();
	arflex_host_destroy(&mon);
	for (unsigned i = 0; i < 2; i++)
		if (src_made[i])
			arflex_port_destroy(&src[i]);
	if (leaked()) {
		fprintf(stderr, "FAIL: objects or children leaked\n");
		failures++;
	}
	if (failures) {
		fprintf(stderr, "debugmon.%s: %d failure(s)\n", argv[1], failures);
		return 1;
	}
	printf("debugmon.%s: ok\n", argv[1]);
	return 0;
}
