/*
 * latency-probe-reader: the single consumer of the latency probe's `samples` stream.
 *
 *   latency-probe-reader --runtime RID --instance INST [--port samples] [--out FILE]
 *                        [--summary FILE] [--count N] [--drain] [--idle-timeout-ms MS]
 *
 * Opens /arflex.<RID>.<INST>.out.<port> read-write as the stream's consumer (rt-core's port
 * API: arflex_port_open + arflex_stream_pop, type arflex.Sample 1.0 checked) and writes each
 * sample as one text line "seq release_ns lateness_ns" to FILE (default: standard output).
 * It stops when
 *   --count N  N samples were read (the rest stays in the ring for the next reader),
 *   --drain    the ring is empty (use after the probe stopped),
 *   SIGINT/SIGTERM  after taking what is in the ring at that moment,
 * and fails (exit 1) when no new sample arrived for --idle-timeout-ms (default 5000).
 *
 * At the end it writes a JSON summary (--summary FILE, else standard error): samples read by
 * this run, sequence gaps, the port's counters (written, published, dropped, delivered, lost,
 * pending = written - dropped - lost - delivered) and, as a cross-check, the statistics the
 * probe's task loop keeps in its control block (/arflex.<RID>.<INST>.ctl, mapped read-only).
 *
 * Not an RT program: it runs at normal priority and sleeps 2 ms between polls.
 * Exit codes: 0 ok, 1 I/O error or idle timeout, 2 usage, 3 segment missing or incompatible.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <getopt.h>
#include <inttypes.h>
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <time.h>

#include "arflex/control.h"
#include "arflex/port.h"
#include "arflex/sys.h"

#include "sample_type.h"

#define POLL_NS 2000000L

static volatile sig_atomic_t stop_requested;

static void on_signal(int sig)
{
	(void)sig;
	stop_requested = 1;
}

static void usage(FILE *f)
{
	fprintf(f,
		"usage: latency-probe-reader --runtime RID --instance INST [--port samples]\n"
		"                            [--out FILE] [--summary FILE] [--count N] [--drain]\n"
		"                            [--idle-timeout-ms MS]\n");
}

static bool parse_u64(const char *s, uint64_t *out)
{
	char *end;
	unsigned long long v;

	if (!s || !*s || *s == '-')
		return false;
	errno = 0;
	v = strtoull(s, &end, 10);
	if (errno || *end)
		return false;
	*out = v;
	return true;
}

/* The probe's control block, mapped read-only for the statistics cross-check. */
struct ctl_map {
	const struct arflex_ctl *ctl;
	size_t len;
};

static int ctl_map_open(struct ctl_map *m, const char *rid, const char *inst)
{
	char name[ARFLEX_OBJ_NAME_SIZE];
	struct stat st;
	void *base;
	int fd, ret;

	m->ctl = NULL;
	ret = arflex_ctl_obj_name(name, sizeof(name), rid, inst, "ctl");
	if (ret < 0)
		return ret;
	fd = arflex_sys_shm_open(name, O_RDONLY, 0);
	if (fd < 0)
		return fd;
	ret = arflex_sys_fstat(fd, &st);
	if (ret < 0)
		goto out_close;
	if ((size_t)st.st_size != ARFLEX_CTL_SIZE) {
		ret = -EMSGSIZE;
		goto out_close;
	}
	ret = arflex_sys_mmap(&base, ARFLEX_CTL_SIZE, PROT_READ, MAP_SHARED, fd, 0);
	if (ret < 0)
		goto out_close;
	ret = arflex_ctl_check(base, ARFLEX_CTL_SIZE);
	if (ret < 0) {
		arflex_sys_munmap(base, ARFLEX_CTL_SIZE);
		goto out_close;
	}
	m->ctl = base;
	m->len = ARFLEX_CTL_SIZE;
out_close:
	arflex_sys_close(fd);
	return ret;
}

static void ctl_map_close(struct ctl_map *m)
{
	if (m->ctl)
		arflex_sys_munmap((void *)m->ctl, m->len);
	m->ctl = NULL;
}

static void print_metric(FILE *f, const char *key, const struct arflex_metric *mt)
{
	fprintf(f, "\"%s\": {\"count\": %" PRIu64 ", \"min\": %" PRIu64 ", \"max\": %" PRIu64
		   ", \"mean\": %.1f, \"avedev_running\": %.1f, \"p50\": %" PRIu64
		   ", \"p99\": %" PRIu64 ", \"p99_9\": %" PRIu64 "}",
		key, mt->count, mt->count ? mt->min_ns : 0, mt->max_ns,
		mt->count ? (double)mt->sum_ns / (double)mt->count : 0.0,
		mt->count ? (double)mt->sum_absdev_ns / (double)mt->count : 0.0,
		arflex_metric_percentile(mt, 50.0), arflex_metric_percentile(mt, 99.0),
		arflex_metric_percentile(mt, 99.9));
}

int main(int argc, char **argv)
{
	static const struct option longopts[] = {
		{ "runtime", required_argument, NULL, 'r' },
		{ "instance", required_argument, NULL, 'i' },
		{ "port", required_argument, NULL, 'p' },
		{ "out", required_argument, NULL, 'o' },
		{ "summary", required_argument, NULL, 's' },
		{ "count", required_argument, NULL, 'n' },
		{ "drain", no_argument, NULL, 'd' },
		{ "idle-timeout-ms", required_argument, NULL, 't' },
		{ "help", no_argument, NULL, 'h' },
		{ NULL, 0, NULL, 0 },
	};
	const char *rid = NULL, *inst = NULL, *port = "samples", *out_path = NULL;
	const char *summary_path = NULL;
	uint64_t count = 0, idle_ms = 5000;
	bool drain = false, idle_failed = false;
	char seg[ARFLEX_OBJ_NAME_SIZE];
	static struct arflex_port sp;
	static struct arflex_stats stats;
	struct arflex_stream_counts sc;
	struct ctl_map cm = { 0 };
	struct arflex_sample s;
	uint64_t nread = 0, gaps = 0, first_seq = 0, last_seq = 0, last_new;
	FILE *out = stdout, *sum = stderr;
	struct sigaction sa;
	int opt, ret, status = 0, ctl_ret;
	char chan[64];

	while ((opt = getopt_long(argc, argv, "", longopts, NULL)) != -1) {
		switch (opt) {
		case 'r': rid = optarg; break;
		case 'i': inst = optarg; break;
		case 'p': port = optarg; break;
		case 'o': out_path = optarg; break;
		case 's': summary_path = optarg; break;
		case 'd': drain = true; break;
		case 'n':
			if (!parse_u64(optarg, &count) || count == 0) {
				fprintf(stderr, "latency-probe-reader: --count needs a positive whole number, not '%s'\n", optarg);
				return 2;
			}
			break;
		case 't':
			if (!parse_u64(optarg, &idle_ms) || idle_ms == 0) {
				fprintf(stderr, "latency-probe-reader: --idle-timeout-ms needs a positive whole number, not '%s'\n", optarg);
				return 2;
			}
			break;
		case 'h': usage(stdout); return 0;
		default: usage(stderr); return 2;
		}
	}
	if (optind != argc || !rid || !inst) {
		fprintf(stderr, "latency-probe-reader: %s\n",
			optind != argc ? "unexpected argument" : "--runtime and --instance are required");
		usage(stderr);
		return 2;
	}
	snprintf(chan, sizeof(chan), "out.%s", port);
	ret = arflex_ctl_obj_name(seg, sizeof(seg), rid, inst, chan);
	if (ret < 0) {
		fprintf(stderr, "latency-probe-reader: invalid runtime id '%s', instance '%s' or port '%s' (%s)\n",
			rid, inst, port, strerror(-ret));
		return 2;
	}
	ret = arflex_port_open(&sp, seg, true, false, ARFLEX_PORT_STREAM, &sample_port_type);
	if (ret < 0) {
		fprintf(stderr, "latency-probe-reader: cannot open %s as a stream of %s %u.%u: %s\n",
			seg, sample_port_type.name, sample_port_type.major, sample_port_type.minor,
			ret == -EPROTOTYPE ? "method or port type differs" : strerror(-ret));
		return 3;
	}
	if (out_path && strcmp(out_path, "-") != 0) {
		out = fopen(out_path, "w");
		if (!out) {
			fprintf(stderr, "latency-probe-reader: cannot write %s: %s\n", out_path, strerror(errno));
			arflex_port_close(&sp);
			return 1;
		}
	}
	memset(&sa, 0, sizeof(sa));
	sa.sa_handler = on_signal;
	sigaction(SIGINT, &sa, NULL);
	sigaction(SIGTERM, &sa, NULL);

	last_new = arflex_sys_now_ns();
	for (;;) {
		bool got = false;
		bool stopping = stop_requested;

		while ((!count || nread < count) && arflex_stream_pop(&sp, &s, sizeof(s)) == 1) {
			if (nread == 0)
				first_seq = s.seq;
			else if (s.seq != last_seq + 1)
				gaps++;
			last_seq = s.seq;
			nread++;
			got = true;
			fprintf(out, "%" PRIu64 " %" PRId64 " %.0f\n", s.seq, s.t_ns, s.value);
		}
		if ((count && nread >= count) || drain || stopping)
			break;
		if (got) {
			last_new = arflex_sys_now_ns();
		} else if (arflex_sys_now_ns() - last_new > idle_ms * 1000000ull) {
			fprintf(stderr, "latency-probe-reader: no sample on %s for %" PRIu64 " ms (probe not running?)\n",
				seg, idle_ms);
			idle_failed = true;
			break;
		}
		nanosleep(&(struct timespec){ 0, POLL_NS }, NULL);
	}
	if (fflush(out) != 0 || (out != stdout && fclose(out) != 0)) {
		fprintf(stderr, "latency-probe-reader: writing the samples failed: %s\n", strerror(errno));
		status = 1;
	}
	if (idle_failed)
		status = 1;

	arflex_stream_counts(&sp, &sc);
	ctl_ret = ctl_map_open(&cm, rid, inst);
	if (!ctl_ret)
		ctl_ret = arflex_ctl_stats_read(cm.ctl, &stats);
	if (summary_path) {
		sum = fopen(summary_path, "w");
		if (!sum) {
			fprintf(stderr, "latency-probe-reader: cannot write %s: %s\n", summary_path, strerror(errno));
			sum = stderr;
			status = 1;
		}
	}
	fprintf(sum, "{\"segment\": \"%s\", \"read\": %" PRIu64 ", \"first_seq\": %" PRIu64
		     ", \"last_seq\": %" PRIu64 ", \"seq_gaps\": %" PRIu64 ",\n",
		seg, nread, first_seq, last_seq, gaps);
	fprintf(sum, " \"stream\": {\"written\": %" PRIu64 ", \"published\": %" PRIu64
		     ", \"dropped\": %" PRIu64 ", \"delivered\": %" PRIu64 ", \"lost\": %" PRIu64
		     ", \"pending\": %" PRId64 "},\n",
		sc.written, sc.published, sc.dropped, sc.delivered, sc.lost,
		(int64_t)(sc.written - sc.dropped - sc.lost - sc.delivered));
	if (ctl_ret < 0) {
		fprintf(sum, " \"ctl\": null, \"ctl_error\": \"%s\"}\n", strerror(-ctl_ret));
	} else {
		fprintf(sum, " \"ctl\": {\"cycles\": %" PRIu64 ", \"overruns\": %" PRIu64
			     ", \"missed_periods\": %" PRIu64 ", \"deadline_misses\": %" PRIu64
			     ", \"update_errors\": %" PRIu64 ", \"sched_fifo\": %s, ",
			stats.cycles, stats.overruns, stats.missed_periods, stats.deadline_misses,
			stats.update_errors,
			(arflex_ctl_flags(cm.ctl) & ARFLEX_FLAG_SCHED_FIFO) ? "true" : "false");
		print_metric(sum, "latency", &stats.latency);
		fputs(", ", sum);
		print_metric(sum, "exec", &stats.exec);
		fputs("}}\n", sum);
	}
	if (sum != stderr && fclose(sum) != 0)
		status = 1;
	ctl_map_close(&cm);
	arflex_port_close(&sp);
	return status;
}
