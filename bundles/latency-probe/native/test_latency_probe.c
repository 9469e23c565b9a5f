/*
 * test_latency_probe - CTest latency.*: the latency probe and its reader tool under the rt-core
 * host API (the DRCR does the same in Java). No timing is asserted: only that samples arrive
 * and that every count is exact.
 *
 *   test_latency_probe <case> <latency-probe exe> <latency-probe-reader exe> <latency-probe.xml>
 *
 * The probe's output, period and the rest come from its contract (arflex_host_load_contract,
 * docs/DECISIONS.md D32/D34); the harness's own choices: SCHED_OTHER, no mlock, no
 * cpu_dma_latency, no heartbeat watchdog, and, for the overflow and errors cases, a shallower
 * queue and a wrong port type on purpose.
 *   cases:
 *     stream    the contract's depth (65536): a first reader takes exactly 200 samples while the probe runs,
 *               a second one drains the rest after STOP; seqs 1..N without a gap, one sample
 *               per cycle (written == cycles of the control block), read == written,
 *               releases one period apart, lateness >= 0.
 *     overflow  depth 64, drop-newest, no reader while running: the reader gets exactly the
 *               first 64, read + dropped == written.
 *     errors    the reader refuses bad options (exit 2) and a missing segment (exit 3) with
 *               a message, and a wrong port type (exit 3).
 *
 * Every case ends by checking that no /dev/shm/arflex.<rid>.* or queue object and no child
 * process is left. Waits are on conditions with deadlines.
 */
#define _GNU_SOURCE
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <mqueue.h>
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
#define WAIT_TIMEOUT (20 * SEC)

static char rid[ARFLEX_ID_MAX + 1];
static char tmpdir[256];
static const char *probe_exe, *reader_exe, *probe_xml;
static struct arflex_host host;
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

static bool leaked(void)
{
	/* /dev/mqueue may not be mounted: the kit also probes the tracked queues by name. */
	th_track(rid, "probe");
	return th_leftovers(rid) > 0 || !th_no_children();
}

/* The probe as its contract declares it; a @depth other than 0 replaces the stream's depth
 * and a @type other than NULL the segment's port type (both on purpose, to test the reader). */
static int make_probe(uint32_t depth, const struct arflex_port_type *type)
{
	static const struct arflex_host_type types[] = { ARFLEX_HOST_TYPE(SAMPLE) };
	static struct arflex_host_contract c;
	struct arflex_host_opts o;
	char err[512];
	int ret = arflex_host_load_contract(&c, probe_xml, types, 1, err, sizeof(err));

	if (ret < 0)
		return fprintf(stderr, "%s\n", err), ret;
	if (c.noutputs != 1 || strcmp(c.output_ports[0], "samples") != 0 ||
	    c.outputs[0].spec.method != ARFLEX_PORT_STREAM)
		return fprintf(stderr, "%s: expected one stream output 'samples'\n", probe_xml), -EINVAL;
	if (depth)
		c.outputs[0].spec.depth = depth;
	if (type)
		c.outputs[0].spec.type = *type;
	arflex_host_contract_opts(&c, rid, "probe", &o);
	/* tests share the machine: SCHED_OTHER, no mlock, and nobody writes the heartbeat */
	o.config.priority = 0;
	o.config.cfg_flags |= ARFLEX_CFG_NO_MLOCK | ARFLEX_CFG_NO_DMA_LATENCY;
	o.config.hb_timeout_ns = 0;
	ret = arflex_host_create(&host, &o);
	if (ret < 0)
		return ret;
	return arflex_host_spawn(&host, probe_exe, NULL, NULL);
}

/* Runs the reader with @extra options (NULL-terminated, at most 6) plus --runtime/--instance,
 * --out and --summary in tmpdir; returns its exit code or -1. */
static int run_reader(const char *tag, const char *const *extra)
{
	char out[300], sum[300];
	char *argv[20];
	int n = 0, status;
	pid_t pid;

	snprintf(out, sizeof(out), "%s/%s.txt", tmpdir, tag);
	snprintf(sum, sizeof(sum), "%s/%s.json", tmpdir, tag);
	argv[n++] = (char *)reader_exe;
	argv[n++] = "--runtime";
	argv[n++] = rid;
	argv[n++] = "--instance";
	argv[n++] = "probe";
	argv[n++] = "--out";
	argv[n++] = out;
	argv[n++] = "--summary";
	argv[n++] = sum;
	for (; extra && *extra && n < 19; extra++)
		argv[n++] = (char *)*extra;
	argv[n] = NULL;
	if (arflex_sys_spawn(&pid, reader_exe, argv, NULL) < 0)
		return -1;
	if (arflex_sys_waitpid(pid, &status, 0) != pid || !WIFEXITED(status))
		return -1;
	return WEXITSTATUS(status);
}

/* The number after "key": in the summary file of @tag, or UINT64_MAX. */
static uint64_t summary_u64(const char *tag, const char *key)
{
	char path[300], buf[4096], pat[64];
	uint64_t v = UINT64_MAX;
	size_t n;
	FILE *f;
	char *p;

	snprintf(path, sizeof(path), "%s/%s.json", tmpdir, tag);
	f = fopen(path, "r");
	if (!f)
		return v;
	n = fread(buf, 1, sizeof(buf) - 1, f);
	fclose(f);
	buf[n] = 0;
	snprintf(pat, sizeof(pat), "\"%s\": ", key);
	p = strstr(buf, pat);
	if (p)
		sscanf(p + strlen(pat), "%" SCNu64, &v);
	return v;
}

struct sample_line {
	uint64_t seq;
	int64_t t_ns;
	int64_t lat_ns;
};

/* Reads the sample lines of @tag into @s (at most @max); returns the count or -1. */
static long read_samples(const char *tag, struct sample_line *s, long max)
{
	char path[300];
	long n = 0;
	FILE *f;

	snprintf(path, sizeof(path), "%s/%s.txt", tmpdir, tag);
	f = fopen(path, "r");
	if (!f)
		return -1;
	while (n < max && fscanf(f, "%" SCNu64 " %" SCNd64 " %" SCNd64, &s[n].seq, &s[n].t_ns,
				 &s[n].lat_ns) == 3)
		n++;
	fclose(f);
	return n;
}

static int wait_cycles(uint64_t n)
{
	static struct arflex_stats st;
	uint64_t deadline = arflex_sys_now_ns() + WAIT_TIMEOUT;

	while (arflex_sys_now_ns() < deadline) {
		if (arflex_ctl_stats_read(host.ctl, &st) == 0 && st.cycles >= n)
			return 0;
		nanosleep(&(struct timespec){ 0, 1000000 }, NULL);
	}
	fprintf(stderr, "only %" PRIu64 " cycles within the deadline (state %u)\n", st.cycles,
		arflex_ctl_state(host.ctl));
	return -ETIMEDOUT;
}

static uint64_t ctl_cycles(void)
{
	static struct arflex_stats st;

	return arflex_ctl_stats_read(host.ctl, &st) == 0 ? st.cycles : UINT64_MAX;
}

static int stop_and_shutdown(void)
{
	if (arflex_host_stop(&host, CALL_TIMEOUT) < 0)
		return -1;
	return 0;
}

static struct sample_line lines[70000];

static int case_stream(void)
{
	static const char *const first[] = { "--count", "200", NULL };
	static const char *const rest[] = { "--drain", NULL };
	uint64_t written, cycles;
	long n1, n2;

	CHECK(make_probe(0, NULL) == 0, "create/spawn");
	CHECK(arflex_host_wait_state(&host, ARFLEX_STATE_READY, WAIT_TIMEOUT) == 0, "READY");
	CHECK(arflex_host_start(&host, CALL_TIMEOUT) == 0, "START");
	CHECK(run_reader("first", first) == 0, "first reader (--count 200) failed");
	CHECK(summary_u64("first", "read") == 200, "first reader read %" PRIu64,
	      summary_u64("first", "read"));
	CHECK(wait_cycles(400) == 0, "cycles");
	CHECK(stop_and_shutdown() == 0, "STOP");
	cycles = ctl_cycles();
	CHECK(run_reader("rest", rest) == 0, "second reader (--drain) failed");
	written = summary_u64("rest", "written");
	CHECK(written == cycles, "written %" PRIu64 " != cycles %" PRIu64, written, cycles);
	CHECK(summary_u64("rest", "dropped") == 0, "dropped %" PRIu64, summary_u64("rest", "dropped"));
	CHECK(summary_u64("rest", "lost") == 0, "lost");
	CHECK(summary_u64("rest", "pending") == 0, "pending %" PRIu64, summary_u64("rest", "pending"));
	CHECK(summary_u64("rest", "delivered") == written, "delivered %" PRIu64 " != written",
	      summary_u64("rest", "delivered"));
	CHECK(summary_u64("rest", "read") + 200 == written, "read %" PRIu64 " + 200 != %" PRIu64,
	      summary_u64("rest", "read"), written);
	CHECK(summary_u64("rest", "cycles") == cycles, "ctl cross-check cycles");
	n1 = read_samples("first", lines, 70000);
	n2 = read_samples("rest", lines + (n1 > 0 ? n1 : 0), 70000 - 200);
	CHECK(n1 == 200 && n2 >= 0 && (uint64_t)(n1 + n2) == written, "lines %ld + %ld", n1, n2);
	for (long i = 0; i < n1 + n2; i++) {
		CHECK(lines[i].seq == (uint64_t)i + 1, "line %ld has seq %" PRIu64, i, lines[i].seq);
		CHECK(lines[i].lat_ns >= 0, "negative lateness %" PRId64, lines[i].lat_ns);
		if (i > 0)
			CHECK(lines[i].t_ns > lines[i - 1].t_ns &&
			      (lines[i].t_ns - lines[i - 1].t_ns) % (int64_t)MS == 0,
			      "release %" PRId64 " after %" PRId64, lines[i].t_ns, lines[i - 1].t_ns);
	}
	CHECK(arflex_host_shutdown(&host, CALL_TIMEOUT) == 0, "SHUTDOWN");
	CHECK(arflex_host_wait_exit(&host, WAIT_TIMEOUT) == 0, "exit");
	CHECK(WIFEXITED(arflex_host_exit_status(&host)) &&
	      WEXITSTATUS(arflex_host_exit_status(&host)) == 0, "exit status");
out:
	return 0;
}

static int case_overflow(void)
{
	static const char *const drain[] = { "--drain", NULL };
	uint64_t written;
	long n;

	CHECK(make_probe(64, NULL) == 0, "create/spawn");
	CHECK(arflex_host_wait_state(&host, ARFLEX_STATE_READY, WAIT_TIMEOUT) == 0, "READY");
	CHECK(arflex_host_start(&host, CALL_TIMEOUT) == 0, "START");
	CHECK(wait_cycles(300) == 0, "cycles");
	CHECK(stop_and_shutdown() == 0, "STOP");
	CHECK(run_reader("all", drain) == 0, "reader failed");
	written = summary_u64("all", "written");
	CHECK(written == ctl_cycles(), "written %" PRIu64 " != cycles", written);
	CHECK(summary_u64("all", "read") == 64, "read %" PRIu64, summary_u64("all", "read"));
	CHECK(summary_u64("all", "read") + summary_u64("all", "dropped") == written,
	      "read %" PRIu64 " + dropped %" PRIu64 " != written %" PRIu64,
	      summary_u64("all", "read"), summary_u64("all", "dropped"), written);
	CHECK(summary_u64("all", "pending") == 0, "pending");
	n = read_samples("all", lines, 70000);
	CHECK(n == 64, "lines %ld", n);
	for (long i = 0; i < n; i++)
		CHECK(lines[i].seq == (uint64_t)i + 1, "drop-newest keeps the first: seq %" PRIu64,
		      lines[i].seq);
	CHECK(arflex_host_shutdown(&host, CALL_TIMEOUT) == 0, "SHUTDOWN");
	CHECK(arflex_host_wait_exit(&host, WAIT_TIMEOUT) == 0, "exit");
out:
	return 0;
}

static int case_errors(void)
{
	static const char *const bad_count[] = { "--count", "-3", NULL };
	static const char *const bad_opt[] = { "--bogus", NULL };
	static const char *const drain[] = { "--drain", NULL };
	static const struct arflex_port_type other = { "arflex.Other", 1, 0, 24 };
	char missing_rid[ARFLEX_ID_MAX + 1];
	char *argv[] = { (char *)reader_exe, "--runtime", missing_rid, "--instance", "probe",
			 "--drain", NULL };
	int status;
	pid_t pid;

	CHECK(run_reader("badcount", bad_count) == 2, "--count -3 not refused");
	CHECK(run_reader("badopt", bad_opt) == 2, "unknown option not refused");
	snprintf(missing_rid, sizeof(missing_rid), "t-lat-none-%ld", (long)getpid());
	CHECK(arflex_sys_spawn(&pid, reader_exe, argv, NULL) == 0, "spawn");
	CHECK(arflex_sys_waitpid(pid, &status, 0) == pid && WIFEXITED(status) &&
	      WEXITSTATUS(status) == 3, "missing segment: status %d", status);
	/* a segment of another type: refused by the port type check */
	CHECK(make_probe(64, &other) == 0, "create/spawn");
	/* the probe itself refuses it too (configure fails: exit 4, state FAILED) */
	CHECK(arflex_host_wait_exit(&host, WAIT_TIMEOUT) == 0, "probe did not exit");
	CHECK(WIFEXITED(arflex_host_exit_status(&host)) &&
	      WEXITSTATUS(arflex_host_exit_status(&host)) == 4, "probe exit status %d",
	      arflex_host_exit_status(&host));
	CHECK(run_reader("wrongtype", drain) == 3, "wrong port type not refused");
out:
	return 0;
}

int main(int argc, char **argv)
{
	static const struct {
		const char *name;
		int (*fn)(void);
	} cases[] = {
		{ "stream", case_stream },
		{ "overflow", case_overflow },
		{ "errors", case_errors },
	};
	int (*fn)(void) = NULL;
	char cmd[300];

	if (argc != 5) {
		fprintf(stderr, "usage: %s stream|overflow|errors <latency-probe> <latency-probe-reader> "
			"<latency-probe.xml>\n", argv[0]);
		return 2;
	}
	for (unsigned i = 0; i < sizeof(cases) / sizeof(cases[0]); i++)
		if (strcmp(argv[1], cases[i].name) == 0)
			fn = cases[i].fn;
	if (!fn) {
		fprintf(stderr, "test_latency_probe: unknown case '%s'\n", argv[1]);
		return 2;
	}
	probe_exe = argv[2];
	reader_exe = argv[3];
	probe_xml = argv[4];
	snprintf(rid, sizeof(rid), "t-lat-%ld", (long)getpid());
	snprintf(tmpdir, sizeof(tmpdir), "/tmp/arflex-latency-test.XXXXXX");
	if (!mkdtemp(tmpdir)) {
		perror("mkdtemp");
		return 1;
	}
	fn();
	arflex_host_destroy(&host);
	if (leaked()) {
		fprintf(stderr, "FAIL: objects or children leaked\n");
		failures++;
	}
	snprintf(cmd, sizeof(cmd), "rm -rf '%s'", tmpdir);
	if (system(cmd) != 0)
		fprintf(stderr, "warning: could not remove %s\n", tmpdir);
	if (failures) {
		fprintf(stderr, "latency.%s: %d failure(s)\n", argv[1], failures);
		return 1;
	}
	printf("latency.%s: ok\n", argv[1]);
	return 0;
}
