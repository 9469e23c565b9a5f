/*
 * arflex-baseline-task - the "pure RT task" contender: the periodic loop of an RT half with
 * no management at all (no control block, no mailbox, no ports, no heartbeat, no parameter
 * table), for side-by-side comparisons with a managed component and with cyclictest.
 *
 * The loop has the shape of rt-core's task loop (and cyclictest's): pin to one CPU, SCHED_FIFO,
 * mlockall, hold /dev/cpu_dma_latency at 0, absolute clock_nanosleep on CLOCK_MONOTONIC, record
 * the wake-up latency, catch up after an overrun and count it. Statistics use rt-core's metric
 * code (arflex_metric_add / arflex_metric_percentile: 100 ns histogram bins, the same numbers a
 * component publishes in its control block). In addition every sample is kept in a buffer
 * allocated and touched before the loop, so that the exact mean absolute deviation and the
 * signed period deviation (actual wake - previous actual wake - period, which can be negative)
 * are reported too.
 *
 * Nothing is printed, allocated or blocked on inside the loop; the results are printed after.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <getopt.h>
#include <inttypes.h>
#include <limits.h>
#include <math.h>
#include <sched.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/utsname.h>
#include <time.h>
#include <unistd.h>

#include "arflex/control.h"
#include "arflex/sys.h"
#include "arflex/task.h"

#define MAX_LOOPS 100000000ull

struct opts {
	uint64_t period_ns;
	int priority;
	int cpu;          /* -1: no affinity */
	uint64_t loops;
	const char *json; /* NULL: no JSON */
	bool no_mlock;
	bool quiet;
};

struct result {
	struct arflex_metric lat;  /* wake-up latency (rt-core metric code) */
	int64_t *lat_ns;           /* every wake-up latency */
	int64_t *dev_ns;           /* signed period deviation, loops - 1 values */
	uint64_t overruns;
	uint64_t missed_periods;
	uint64_t sleep_errors;
	bool fifo, locked, pinned, dma;
	int sched_err, mlock_err, affinity_err, dma_err;
	uint64_t started_ns, ended_ns;
};

static void usage(FILE *f, const char *argv0)
{
	fprintf(f,
		"usage: %s [--period-us N] [--priority P] [--cpu C] [--loops N] [--json FILE]\n"
		"          [--no-mlock] [--quiet]\n"
		"  --period-us N   period in microseconds (default 1000)\n"
		"  --priority P    SCHED_FIFO priority 1..99, 0 = SCHED_OTHER (default 80)\n"
		"  --cpu C         pin to CPU C (default: no affinity)\n"
		"  --loops N       cycles to measure (default 4000)\n"
		"  --json FILE     also write the results as JSON to FILE\n"
		"  --no-mlock      do not call mlockall\n"
		"  --quiet         no table on stdout\n",
		argv0);
}

static int parse_u64(const char *opt, const char *s, uint64_t lo, uint64_t hi, uint64_t *out)
{
	char *end;
	unsigned long long v;

	errno = 0;
	v = strtoull(s, &end, 10);
	if (errno || end == s || *end || s[0] == '-' || v < lo || v > hi) {
		fprintf(stderr, "arflex-baseline-task: %s: '%s' is not an integer in %" PRIu64
			"..%" PRIu64 "\n", opt, s, lo, hi);
		return -EINVAL;
	}
	*out = v;
	return 0;
}

static int parse_args(int argc, char **argv, struct opts *o)
{
	static const struct option longopts[] = {
		{ "period-us", required_argument, NULL, 'p' },
		{ "priority", required_argument, NULL, 'P' },
		{ "cpu", required_argument, NULL, 'c' },
		{ "loops", required_argument, NULL, 'l' },
		{ "json", required_argument, NULL, 'j' },
		{ "no-mlock", no_argument, NULL, 'm' },
		{ "quiet", no_argument, NULL, 'q' },
		{ "help", no_argument, NULL, 'h' },
		{ NULL, 0, NULL, 0 },
	};
	long ncpu = sysconf(_SC_NPROCESSORS_CONF);
	uint64_t v;
	int c;

	o->period_ns = 1000000;
	o->priority = 80;
	o->cpu = -1;
	o->loops = 4000;
	o->json = NULL;
	o->no_mlock = false;
	o->quiet = false;
	while ((c = getopt_long(argc, argv, "", longopts, NULL)) != -1) {
		switch (c) {
		case 'p':
			if (parse_u64("--period-us", optarg, 10, 10000000, &v))
				return 2;
			o->period_ns = v * 1000;
			break;
		case 'P':
			if (parse_u64("--priority", optarg, 0, 99, &v))
				return 2;
			o->priority = (int)v;
			break;
		case 'c':
			if (parse_u64("--cpu", optarg, 0, (uint64_t)(ncpu > 0 ? ncpu - 1 : 0), &v))
				return 2;
			if (v > 63) {
				fprintf(stderr, "arflex-baseline-task: --cpu: CPUs above 63 are not "
					"supported\n");
				return 2;
			}
			o->cpu = (int)v;
			break;
		case 'l':
			if (parse_u64("--loops", optarg, 2, MAX_LOOPS, &v))
				return 2;
			o->loops = v;
			break;
		case 'j':
			if (!*optarg) {
				fprintf(stderr, "arflex-baseline-task: --json: empty file name\n");
				return 2;
			}
			o->json = optarg;
			break;
		case 'm':
			o->no_mlock = true;
			break;
		case 'q':
			o->quiet = true;
			break;
		case 'h':
			usage(stdout, argv[0]);
			return 1;
		default:
			usage(stderr, argv[0]);
			return 2;
		}
	}
	if (optind < argc) {
		fprintf(stderr, "arflex-baseline-task: unexpected argument '%s'\n", argv[optind]);
		usage(stderr, argv[0]);
		return 2;
	}
	return 0;
}

/* Set-up before the loop, like the task module: affinity, mlockall, FIFO, dma latency. */
static int setup(const struct opts *o, struct result *r)
{
	if (o->cpu >= 0) {
		r->affinity_err = arflex_sys_set_affinity(UINT64_C(1) << o->cpu);
		r->pinned = r->affinity_err == 0;
	}
	if (!o->no_mlock) {
		r->mlock_err = arflex_sys_mlockall(MCL_CURRENT | MCL_FUTURE);
		r->locked = r->mlock_err == 0;
	}
	if (o->priority > 0) {
		r->sched_err = arflex_sys_set_sched(SCHED_FIFO, o->priority);
		r->fifo = r->sched_err == 0;
	}
	{
		int fd = arflex_sys_open("/dev/cpu_dma_latency", O_WRONLY, 0);
		int32_t zero = 0;

		if (fd < 0) {
			r->dma_err = fd;
			return -1;
		}
		r->dma_err = arflex_sys_write_all(fd, &zero, sizeof(zero));
		r->dma = r->dma_err == 0;
		if (!r->dma) {
			arflex_sys_close(fd);
			return -1;
		}
		return fd; /* held open until the end */
	}
}

static void warn_setup(const struct opts *o, const struct result *r)
{
	if (o->cpu >= 0 && !r->pinned)
		fprintf(stderr, "arflex-baseline-task: warning: CPU affinity refused (%s)\n",
			strerror(-r->affinity_err));
	if (!o->no_mlock && !r->locked)
		fprintf(stderr, "arflex-baseline-task: warning: mlockall refused (%s)\n",
			strerror(-r->mlock_err));
	if (o->priority > 0 && !r->fifo)
		fprintf(stderr, "arflex-baseline-task: warning: SCHED_FIFO %d refused (%s), "
			"running SCHED_OTHER\n", o->priority, strerror(-r->sched_err));
	if (!r->dma)
		fprintf(stderr, "arflex-baseline-task: warning: /dev/cpu_dma_latency not held "
			"(%s)\n", strerror(-r->dma_err));
}

/* The measured loop. Nothing here prints, allocates or blocks except the sleep. */
static void run_loop(const struct opts *o, struct result *r)
{
	const uint64_t period = o->period_ns;
	uint64_t next, prev_wake = 0;

	next = arflex_sys_now_ns() + period;
	r->started_ns = next;
	for (uint64_t i = 0; i < o->loops; i++) {
		uint64_t wake, end;

		if (arflex_sys_sleep_until(next) < 0)
			r->sleep_errors++;
		wake = arflex_sys_now_ns();
		r->lat_ns[i] = wake > next ? (int64_t)(wake - next) : 0;
		arflex_metric_add(&r->lat, (uint64_t)r->lat_ns[i]);
		if (i > 0)
			r->dev_ns[i - 1] = (int64_t)(wake - prev_wake) - (int64_t)period;
		prev_wake = wake;
		end = arflex_sys_now_ns();
		next += period;
		if (next <= end) {
			uint64_t missed = (end - next) / period + 1;

			next += missed * period;
			r->overruns++;
			r->missed_periods += missed;
		}
	}
	r->ended_ns = arflex_sys_now_ns();
}

struct summary {
	double mean, avedev;
	int64_t min, max;
};

static struct summary summarize(const int64_t *v, uint64_t n)
{
	struct summary s = { 0.0, 0.0, INT64_MAX, INT64_MIN };
	double sum = 0.0, dev = 0.0;

	for (uint64_t i = 0; i < n; i++) {
		sum += (double)v[i];
		if (v[i] < s.min)
			s.min = v[i];
		if (v[i] > s.max)
			s.max = v[i];
	}
	s.mean = n ? sum / (double)n : 0.0;
	for (uint64_t i = 0; i < n; i++)
		dev += fabs((double)v[i] - s.mean);
	s.avedev = n ? dev / (double)n : 0.0;
	return s;
}

static int cmp_i64(const void *a, const void *b)
{
	int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;

	return (x > y) - (x < y);
}

/* Exact percentile (nearest rank) of a sorted array. */
static int64_t pct_sorted(const int64_t *v, uint64_t n, double p)
{
	uint64_t rank;

	if (!n)
		return 0;
	rank = (uint64_t)ceil(p / 100.0 * (double)n);
	if (rank < 1)
		rank = 1;
	return v[rank - 1];
}

static void print_table(const struct opts *o, const struct result *r, struct summary ls,
			struct summary ds, const int64_t *lat_sorted, const int64_t *dev_sorted,
			uint64_t ndev)
{
	const struct arflex_metric *m = &r->lat;

	char cpu[32];

	if (o->cpu >= 0)
		snprintf(cpu, sizeof(cpu), "%d%s", o->cpu, r->pinned ? "" : " (refused)");
	else
		snprintf(cpu, sizeof(cpu), "any");
	printf("arflex-baseline-task: %" PRIu64 " cycles of %" PRIu64 " us, %s %d, cpu %s, "
	       "mlock %s, cpu_dma_latency %s\n",
	       m->count, o->period_ns / 1000, r->fifo ? "SCHED_FIFO" : "SCHED_OTHER",
	       r->fifo ? o->priority : 0, cpu, r->locked ? "yes" : "no", r->dma ? "held" : "no");
	printf("%-26s %10s %10s %10s %10s %10s %10s %10s\n", "ns", "min", "avg", "max",
	       "avedev", "p50", "p99", "p99.9");
	printf("%-26s %10" PRIu64 " %10.0f %10" PRIu64 " %10.0f %10" PRIu64 " %10" PRIu64
	       " %10" PRIu64 "\n", "wake-up latency", m->min_ns, ls.mean, m->max_ns, ls.avedev,
	       arflex_metric_percentile(m, 50.0), arflex_metric_percentile(m, 99.0),
	       arflex_metric_percentile(m, 99.9));
	printf("%-26s %10" PRIu64 " %10.0f %10" PRIu64 " %10.0f %10" PRId64 " %10" PRId64
	       " %10" PRId64 "\n", "  same, exact percentiles", m->min_ns, ls.mean, m->max_ns,
	       ls.avedev, pct_sorted(lat_sorted, m->count, 50.0),
	       pct_sorted(lat_sorted, m->count, 99.0), pct_sorted(lat_sorted, m->count, 99.9));
	printf("%-26s %10" PRId64 " %10.0f %10" PRId64 " %10.0f %10" PRId64 " %10" PRId64
	       " %10" PRId64 "\n", "period deviation (signed)", ds.min, ds.mean, ds.max,
	       ds.avedev, pct_sorted(dev_sorted, ndev, 50.0), pct_sorted(dev_sorted, ndev, 99.0),
	       pct_sorted(dev_sorted, ndev, 99.9));
	printf("overruns %" PRIu64 ", missed periods %" PRIu64 ", sleep errors %" PRIu64 "\n",
	       r->overruns, r->missed_periods, r->sleep_errors);
	printf("(first row: percentiles from rt-core's histogram, upper edge of 100 ns bins, the\n"
	       " max for samples >= 200 us; second row: exact percentiles; avedev exact)\n");
}

static int write_json(const char *path, const struct opts *o, const struct result *r,
		      struct summary ls, struct summary ds, const int64_t *lat_sorted,
		      const int64_t *dev_sorted, uint64_t n)
{
	const struct arflex_metric *m = &r->lat;
	struct utsname u;
	FILE *f = fopen(path, "w");

	if (!f) {
		fprintf(stderr, "arflex-baseline-task: --json %s: %s\n", path, strerror(errno));
		return -1;
	}
	if (uname(&u) != 0)
		memset(&u, 0, sizeof(u));
	fprintf(f, "{\n  \"tool\": \"arflex-baseline-task\",\n");
	fprintf(f, "  \"kernel\": \"%s %s\",\n  \"machine\": \"%s\",\n", u.sysname, u.release,
		u.machine);
	fprintf(f, "  \"period_ns\": %" PRIu64 ",\n  \"loops\": %" PRIu64 ",\n", o->period_ns,
		o->loops);
	fprintf(f, "  \"priority\": %d,\n  \"sched_fifo\": %s,\n  \"cpu\": %d,\n  \"pinned\": %s,\n",
		o->priority, r->fifo ? "true" : "false", o->cpu, r->pinned ? "true" : "false");
	fprintf(f, "  \"mlockall\": %s,\n  \"cpu_dma_latency\": %s,\n",
		r->locked ? "true" : "false", r->dma ? "true" : "false");
	fprintf(f, "  \"overruns\": %" PRIu64 ",\n  \"missed_periods\": %" PRIu64 ",\n"
		"  \"sleep_errors\": %" PRIu64 ",\n", r->overruns, r->missed_periods,
		r->sleep_errors);
	fprintf(f, "  \"wakeup_latency_ns\": {\"definition\": \"actual wake - planned release\", "
		"\"count\": %" PRIu64 ", \"min\": %" PRIu64 ", \"avg\": %.1f, \"max\": %" PRIu64
		", \"avedev\": %.1f, \"avedev_running\": %.1f, \"p50\": %" PRIu64 ", \"p99\": %"
		PRIu64 ", \"p99_9\": %" PRIu64 ", \"p50_exact\": %" PRId64 ", \"p99_exact\": %"
		PRId64 ", \"p99_9_exact\": %" PRId64 "},\n",
		m->count, m->min_ns, ls.mean, m->max_ns, ls.avedev,
		m->count ? (double)m->sum_absdev_ns / (double)m->count : 0.0,
		arflex_metric_percentile(m, 50.0), arflex_metric_percentile(m, 99.0),
		arflex_metric_percentile(m, 99.9), pct_sorted(lat_sorted, n, 50.0),
		pct_sorted(lat_sorted, n, 99.0), pct_sorted(lat_sorted, n, 99.9));
	fprintf(f, "  \"period_deviation_ns\": {\"definition\": \"actual wake - previous actual "
		"wake - period (signed)\", \"count\": %" PRIu64 ", \"min\": %" PRId64 ", \"avg\": "
		"%.1f, \"max\": %" PRId64 ", \"avedev\": %.1f, \"p50\": %" PRId64 ", \"p99\": %"
		PRId64 ", \"p99_9\": %" PRId64 "},\n",
		n - 1, ds.min, ds.mean, ds.max, ds.avedev, pct_sorted(dev_sorted, n - 1, 50.0),
		pct_sorted(dev_sorted, n - 1, 99.0), pct_sorted(dev_sorted, n - 1, 99.9));
	fprintf(f, "  \"histogram_bin_ns\": %u,\n  \"latency_histogram\": [", ARFLEX_HIST_BIN_NS);
	{
		unsigned last = 0;

		for (unsigned i = 0; i <= ARFLEX_HIST_BINS; i++)
			if (m->hist[i])
				last = i;
		for (unsigned i = 0; i <= last; i++)
			fprintf(f, "%s%" PRIu64, i ? "," : "", m->hist[i]);
	}
	fprintf(f, "]\n}\n");
	if (fclose(f) != 0) {
		fprintf(stderr, "arflex-baseline-task: --json %s: %s\n", path, strerror(errno));
		return -1;
	}
	return 0;
}

int main(int argc, char **argv)
{
	struct opts o;
	static struct result r;
	struct summary ls, ds;
	int ret, dma_fd;

	ret = parse_args(argc, argv, &o);
	if (ret)
		return ret == 1 ? 0 : 2;
	r.lat_ns = calloc(o.loops, sizeof(int64_t));
	r.dev_ns = calloc(o.loops, sizeof(int64_t));
	if (!r.lat_ns || !r.dev_ns) {
		fprintf(stderr, "arflex-baseline-task: cannot allocate %" PRIu64 " samples\n",
			o.loops);
		free(r.lat_ns);
		free(r.dev_ns);
		return 1;
	}
	arflex_metric_reset(&r.lat);
	dma_fd = setup(&o, &r);
	warn_setup(&o, &r);
	/* Touch the sample buffers so the loop never page-faults (mlockall also locks them). */
	memset(r.lat_ns, 0, o.loops * sizeof(int64_t));
	memset(r.dev_ns, 0, o.loops * sizeof(int64_t));

	run_loop(&o, &r);

	if (o.priority > 0 && r.fifo)
		arflex_sys_set_sched(SCHED_OTHER, 0);
	if (dma_fd >= 0)
		arflex_sys_close(dma_fd);
	ls = summarize(r.lat_ns, o.loops);
	ds = summarize(r.dev_ns, o.loops - 1);
	qsort(r.lat_ns, o.loops, sizeof(int64_t), cmp_i64);
	qsort(r.dev_ns, o.loops - 1, sizeof(int64_t), cmp_i64);
	if (!o.quiet)
		print_table(&o, &r, ls, ds, r.lat_ns, r.dev_ns, o.loops - 1);
	ret = 0;
	if (o.json && write_json(o.json, &o, &r, ls, ds, r.lat_ns, r.dev_ns, o.loops) < 0)
		ret = 1;
	free(r.lat_ns);
	free(r.dev_ns);
	return ret;
}
