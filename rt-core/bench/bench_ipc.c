/*
 * arflex-bench-ipc - IPC costs of rt-core against their raw floors, measured in one run with
 * two processes pinned to different CPUs.
 *
 * Cases (each: warm-up samples discarded, then N samples; the two cases of a comparison run
 * interleaved, in R rounds of N/R samples each with alternating order, so that both see the
 * same machine even when the load from elsewhere drifts):
 *   raw-shm     one-way latency, raw shared memory: the writer stores a CLOCK_MONOTONIC
 *               timestamp and then a sequence word (release); the reader spins on the word
 *               (acquire) and records now - timestamp. The floor of any shm transport.
 *   state-port  one-way latency, arflex state port: the writer arflex_state_write_at()s the
 *               timestamp with itself as the slot's stamp (as a producer that stamps its
 *               value does; arflex_state_write would read the clock once more, about 30 ns
 *               here, D30); the reader spins on arflex_state_read() until it returns a new
 *               value and records now - timestamp.
 *   raw-mq      round trip over two raw POSIX message queues (same attributes as a mailbox:
 *               maxmsg 8, msgsize 512): send 512 bytes, the peer receives and sends them back.
 *   mailbox     round trip through rt-core's mailbox API: arflex_mailbox_call() from the
 *               manager side (arflex_mailbox_create) to a peer that arflex_mailbox_attach()es,
 *               arflex_mailbox_recv()s and arflex_mailbox_send()s the reply.
 * For the one-way cases both sides use the same acknowledgement (a raw shm word written by the
 * reader, awaited by the writer) so the only difference is the forward transport.
 *
 * Every object it creates is named /arflex.bench-<pid>.* and removed on every exit path
 * (normal end, error, SIGINT/SIGTERM/SIGHUP); the child dies with the parent
 * (PR_SET_PDEATHSIG) and every spin has a deadline.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <getopt.h>
#include <inttypes.h>
#include <limits.h>
#include <math.h>
#include <mqueue.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/utsname.h>
#include <sys/wait.h>
#include <unistd.h>

#include "arflex/control.h"
#include "arflex/mailbox.h"
#include "arflex/port.h"
#include "arflex/sys.h"

#define SEC UINT64_C(1000000000)
#define SPIN_TIMEOUT (10 * SEC) /* a peer silent for this long is dead */
#define MQ_MSG 512
/* Targets on the medians: state port issue 18 (port ABI 2.0, D30; issue 2 had 1.5), mailbox
 * issue 2. */
#define TARGET_PORT 1.3
#define TARGET_MAILBOX 1.1

enum { C_RAW_SHM, C_STATE_PORT, C_RAW_MQ, C_MAILBOX, C_COUNT };
static const char *const case_name[C_COUNT] = { "raw-shm", "state-port", "raw-mq", "mailbox" };

struct opts {
	uint64_t n_port, n_mq, warmup;
	unsigned rounds;
	int cpu_a, cpu_b;
	int priority;
	char json[PATH_MAX];
};

/* The raw shared segment: the floor's forward words, acks and the phase barrier, each on its
 * own cache line. */
struct shared {
	_Alignas(64) _Atomic uint64_t seq;    /* raw-shm: sample index + 1 */
	_Atomic uint64_t stamp;               /* raw-shm: timestamp */
	_Alignas(64) _Atomic uint64_t ack;    /* reader -> writer: sample index + 1 */
	_Alignas(64) _Atomic uint64_t phase;  /* child: case it is ready for */
	_Atomic int64_t child_error;          /* child: 0 or -errno */
};

/* Names of everything created; removal is idempotent and async-signal safe. */
static char raw_name[ARFLEX_OBJ_NAME_SIZE], port_name[ARFLEX_OBJ_NAME_SIZE];
static char mq_a_name[ARFLEX_OBJ_NAME_SIZE], mq_b_name[ARFLEX_OBJ_NAME_SIZE];
static char mb_cmd_name[ARFLEX_OBJ_NAME_SIZE], mb_rsp_name[ARFLEX_OBJ_NAME_SIZE];
static volatile pid_t child_pid;

static void remove_objects(void)
{
	/* shm_unlink and mq_unlink are plain unlink syscalls: fine from a signal handler. */
	if (raw_name[0])
		shm_unlink(raw_name);
	if (port_name[0])
		shm_unlink(port_name);
	if (mq_a_name[0])
		mq_unlink(mq_a_name);
	if (mq_b_name[0])
		mq_unlink(mq_b_name);
	if (mb_cmd_name[0])
		mq_unlink(mb_cmd_name);
	if (mb_rsp_name[0])
		mq_unlink(mb_rsp_name);
}

/* Checks by name that nothing created here still exists (works without /dev/mqueue being
 * mounted). */
static bool objects_gone(void)
{
	const char *shm[] = { raw_name, port_name };
	const char *mq[] = { mq_a_name, mq_b_name, mb_cmd_name, mb_rsp_name };
	bool gone = true;

	for (unsigned i = 0; i < 2; i++) {
		int fd = shm[i][0] ? shm_open(shm[i], O_RDONLY, 0) : -1;

		if (fd >= 0) {
			fprintf(stderr, "arflex-bench-ipc: %s was left behind\n", shm[i]);
			close(fd);
			gone = false;
		}
	}
	for (unsigned i = 0; i < 4; i++) {
		mqd_t q = mq[i][0] ? mq_open(mq[i], O_RDONLY) : (mqd_t)-1;

		if (q != (mqd_t)-1) {
			fprintf(stderr, "arflex-bench-ipc: %s was left behind\n", mq[i]);
			mq_close(q);
			gone = false;
		}
	}
	return gone;
}

static void on_signal(int sig)
{
	remove_objects();
	if (child_pid > 0) {
		kill(child_pid, SIGKILL);
		waitpid(child_pid, NULL, 0);
	}
	signal(sig, SIG_DFL);
	raise(sig);
}

static void usage(FILE *f, const char *argv0)
{
	fprintf(f,
		"usage: %s [--samples N] [--mq-samples N] [--warmup N] [--rounds R] [--cpus A,B]\n"
		"          [--priority P] [--json FILE]\n"
		"  --samples N     one-way samples per shm case (default 100000)\n"
		"  --mq-samples N  round trips per queue case (default 20000)\n"
		"  --warmup N      discarded samples of each case before the first round (default 2000)\n"
		"  --rounds R      the compared cases alternate in R rounds of N/R samples (default 10)\n"
		"  --cpus A,B      CPU of the writer/requester and of the reader/server (default 0,1)\n"
		"  --priority P    SCHED_FIFO priority of both processes, 0 = SCHED_OTHER (default 0)\n"
		"  --json FILE     where to write the results (default: bench-ipc.json in the build\n"
		"                  directory, the parent of this executable's bin/)\n",
		argv0);
}

static int parse_u64(const char *opt, const char *s, uint64_t lo, uint64_t hi, uint64_t *out)
{
	char *end;
	unsigned long long v;

	errno = 0;
	v = strtoull(s, &end, 10);
	if (errno || end == s || *end || s[0] == '-' || v < lo || v > hi) {
		fprintf(stderr, "arflex-bench-ipc: %s: '%s' is not an integer in %" PRIu64 "..%"
			PRIu64 "\n", opt, s, lo, hi);
		return -1;
	}
	*out = v;
	return 0;
}

static int parse_args(int argc, char **argv, struct opts *o)
{
	static const struct option longopts[] = {
		{ "samples", required_argument, NULL, 's' },
		{ "mq-samples", required_argument, NULL, 'm' },
		{ "warmup", required_argument, NULL, 'w' },
		{ "rounds", required_argument, NULL, 'r' },
		{ "cpus", required_argument, NULL, 'c' },
		{ "priority", required_argument, NULL, 'p' },
		{ "json", required_argument, NULL, 'j' },
		{ "help", no_argument, NULL, 'h' },
		{ NULL, 0, NULL, 0 },
	};
	long ncpu = sysconf(_SC_NPROCESSORS_ONLN);
	uint64_t v;
	int c;

	o->n_port = 100000;
	o->n_mq = 20000;
	o->warmup = 2000;
	o->rounds = 10;
	o->cpu_a = 0;
	o->cpu_b = ncpu > 1 ? 1 : 0;
	o->priority = 0;
	o->json[0] = 0;
	while ((c = getopt_long(argc, argv, "", longopts, NULL)) != -1) {
		switch (c) {
		case 's':
			if (parse_u64("--samples", optarg, 1, 100000000, &o->n_port))
				return 2;
			break;
		case 'm':
			if (parse_u64("--mq-samples", optarg, 1, 100000000, &o->n_mq))
				return 2;
			break;
		case 'w':
			if (parse_u64("--warmup", optarg, 0, 10000000, &o->warmup))
				return 2;
			break;
		case 'r':
			if (parse_u64("--rounds", optarg, 1, 1000, &v))
				return 2;
			o->rounds = (unsigned)v;
			break;
		case 'c': {
			int a, b, n = 0;

			if (sscanf(optarg, "%d,%d%n", &a, &b, &n) != 2 || optarg[n] || a < 0 ||
			    b < 0 || a >= ncpu || b >= ncpu || a > 63 || b > 63) {
				fprintf(stderr, "arflex-bench-ipc: --cpus: '%s' is not two CPU numbers "
					"A,B below %ld\n", optarg, ncpu);
				return 2;
			}
			o->cpu_a = a;
			o->cpu_b = b;
			break;
		}
		case 'p':
			if (parse_u64("--priority", optarg, 0, 99, &v))
				return 2;
			o->priority = (int)v;
			break;
		case 'j':
			if (!*optarg || strlen(optarg) >= sizeof(o->json)) {
				fprintf(stderr, "arflex-bench-ipc: --json: bad file name\n");
				return 2;
			}
			snprintf(o->json, sizeof(o->json), "%s", optarg);
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
		fprintf(stderr, "arflex-bench-ipc: unexpected argument '%s'\n", argv[optind]);
		return 2;
	}
	if (!o->json[0]) {
		char exe[PATH_MAX];
		ssize_t len = readlink("/proc/self/exe", exe, sizeof(exe) - 1);
		char *slash;

		if (len <= 0) {
			fprintf(stderr, "arflex-bench-ipc: cannot find the build directory; give "
				"--json FILE\n");
			return 2;
		}
		exe[len] = 0;
		/* <build>/bin/arflex-bench-ipc -> <build>/bench-ipc.json */
		for (int up = 0; up < 2 && (slash = strrchr(exe, '/')); up++)
			*slash = 0;
		if (snprintf(o->json, sizeof(o->json), "%s/bench-ipc.json", exe[0] ? exe : ".") >=
		    (int)sizeof(o->json)) {
			fprintf(stderr, "arflex-bench-ipc: build directory path too long\n");
			return 2;
		}
	}
	return 0;
}

static void setup_cpu(int cpu, int priority, const char *who)
{
	int r = arflex_sys_set_affinity(UINT64_C(1) << cpu);

	if (r < 0)
		fprintf(stderr, "arflex-bench-ipc: warning: %s: pinning to CPU %d refused (%s)\n",
			who, cpu, strerror(-r));
	if (priority > 0) {
		r = arflex_sys_set_sched(SCHED_FIFO, priority);
		if (r < 0)
			fprintf(stderr, "arflex-bench-ipc: warning: %s: SCHED_FIFO %d refused (%s)\n",
				who, priority, strerror(-r));
	}
}

/* Spin until *w == want (acquire). 0, or -ETIMEDOUT after SPIN_TIMEOUT. */
static int spin_eq(_Atomic uint64_t *w, uint64_t want)
{
	uint64_t deadline = 0;

	for (unsigned i = 0;; i++) {
		if (atomic_load_explicit(w, memory_order_acquire) == want)
			return 0;
		if ((i & 4095) == 0) {
			uint64_t now = arflex_sys_now_ns();

			if (!deadline)
				deadline = now + SPIN_TIMEOUT;
			else if (now > deadline)
				return -ETIMEDOUT;
		}
	}
}

/* ---- the schedule: rounds of interleaved segments --------------------------------- */

/*
 * Both processes follow the same schedule. Round 0 is the warm-up (o->warmup samples of each
 * case, discarded); rounds 1..R split the N samples of each case evenly. In each round the
 * two cases being compared run one after the other, in alternating order, so that both see
 * the same machine (load from elsewhere drifts over a run; interleaving spreads it evenly).
 */
static uint64_t seg_count(const struct opts *o, unsigned round, uint64_t n)
{
	if (round == 0)
		return o->warmup;
	return n / o->rounds + (round == o->rounds ? n % o->rounds : 0);
}

/* Case run at position @k (0 or 1) of round @round, for the pair (@a, @b). */
static int seg_case(unsigned round, int k, int a, int b)
{
	return (round % 2 == 0) == (k == 0) ? a : b;
}

/* ---- child: reader of the one-way cases, server of the round-trip cases ------------- */

/* Spins on a state port until a new value arrives; returns its stamp in *@stamp. */
static int read_port(struct arflex_port *p, uint64_t *stamp)
{
	uint64_t deadline = 0;

	for (unsigned k = 0;; k++) {
		if (arflex_state_read(p, stamp, sizeof(*stamp), NULL) == 1)
			return 0;
		if ((k & 4095) == 0) {
			uint64_t now = arflex_sys_now_ns();

			if (!deadline)
				deadline = now + SPIN_TIMEOUT;
			else if (now > deadline)
				return -ETIMEDOUT;
		}
	}
}

static int child_one_way(const struct opts *o, struct shared *sh, uint64_t *samples,
			 uint64_t *seg)
{
	struct arflex_port p;
	uint64_t raw_n = 0, ack_n = 0, rec[2] = { 0, 0 };
	int r = arflex_port_open(&p, port_name, false, false, ARFLEX_PORT_STATE, NULL);

	if (r)
		return r;
	for (unsigned round = 0; round <= o->rounds; round++) {
		for (int k = 0; k < 2; k++) {
			int c = seg_case(round, k, C_RAW_SHM, C_STATE_PORT);
			uint64_t n = seg_count(o, round, o->n_port);
			uint64_t *out = samples + (c == C_RAW_SHM ? 0 : o->n_port);

			atomic_store_explicit(&sh->phase, ++*seg, memory_order_release);
			for (uint64_t i = 0; i < n; i++) {
				uint64_t stamp, lat;

				if (c == C_RAW_SHM) {
					r = spin_eq(&sh->seq, ++raw_n);
					stamp = atomic_load_explicit(&sh->stamp,
								     memory_order_relaxed);
				} else {
					r = read_port(&p, &stamp);
				}
				lat = arflex_sys_now_ns() - stamp;
				if (r)
					goto out;
				if (round > 0)
					out[rec[c]++] = lat;
				atomic_store_explicit(&sh->ack, ++ack_n, memory_order_release);
			}
		}
	}
out:
	arflex_port_close(&p);
	return r;
}

static int child_round_trip(const struct opts *o, struct shared *sh, const char *rid,
			    mqd_t rx, mqd_t tx, uint64_t *seg)
{
	struct arflex_mailbox mb;
	struct arflex_msg m;
	char buf[MQ_MSG];
	int r = arflex_mailbox_attach(&mb, rid, "mbox");

	if (r)
		return r;
	for (unsigned round = 0; round <= o->rounds && r == 0; round++) {
		for (int k = 0; k < 2 && r == 0; k++) {
			int c = seg_case(round, k, C_RAW_MQ, C_MAILBOX);
			uint64_t n = seg_count(o, round, o->n_mq);

			atomic_store_explicit(&sh->phase, ++*seg, memory_order_release);
			for (uint64_t i = 0; i < n && r == 0; i++) {
				if (c == C_RAW_MQ) {
					struct timespec dl = arflex_sys_realtime_in(SPIN_TIMEOUT);

					if (mq_timedreceive(rx, buf, sizeof(buf), NULL, &dl) != MQ_MSG ||
					    mq_send(tx, buf, MQ_MSG, 0) != 0)
						r = -errno;
				} else {
					r = arflex_mailbox_recv(&mb, &m, SPIN_TIMEOUT);
					if (r)
						break;
					m.flags |= ARFLEX_MSG_REPLY;
					m.status = 0;
					r = arflex_mailbox_send(&mb, &m, SPIN_TIMEOUT);
				}
			}
		}
	}
	arflex_mailbox_deinit(&mb); /* attached: closes, never unlinks */
	return r;
}

static void child_main(const struct opts *o, struct shared *sh, uint64_t *samples,
		       const char *rid, mqd_t mq_a, mqd_t mq_b)
{
	uint64_t seg = 0;
	int r;

	prctl(PR_SET_PDEATHSIG, SIGKILL);
	if (getppid() == 1)
		_exit(1);
	setup_cpu(o->cpu_b, o->priority, "reader");
	r = child_one_way(o, sh, samples, &seg);
	if (r == 0)
		r = child_round_trip(o, sh, rid, mq_a, mq_b, &seg);
	if (r == 0)
		_exit(0);
	atomic_store_explicit(&sh->child_error, r, memory_order_release);
	_exit(1);
}

/* ---- parent: writer of the one-way cases, requester of the round trips -------------- */

/* Waits until the peer reached segment @seg (it may be further on if segments were empty). */
static int wait_phase(struct shared *sh, uint64_t seg, int c)
{
	uint64_t deadline = arflex_sys_now_ns() + SPIN_TIMEOUT;
	int r = 0;

	while (atomic_load_explicit(&sh->phase, memory_order_acquire) < seg) {
		if (arflex_sys_now_ns() > deadline) {
			r = -ETIMEDOUT;
			break;
		}
	}

	if (r)
		fprintf(stderr, "arflex-bench-ipc: %s: the reader process did not get ready\n",
			case_name[c]);
	return r;
}

/* Runs the one-way schedule as the writer. On failure *@failed is the case. */
static int parent_one_way(const struct opts *o, struct shared *sh, struct arflex_port *p,
			  uint64_t *seg, int *failed)
{
	uint64_t raw_n = 0, ack_n = 0;

	for (unsigned round = 0; round <= o->rounds; round++) {
		for (int k = 0; k < 2; k++) {
			int c = seg_case(round, k, C_RAW_SHM, C_STATE_PORT);
			uint64_t n = seg_count(o, round, o->n_port);
			int r;

			*failed = c;
			if ((r = wait_phase(sh, ++*seg, c)))
				return r;
			for (uint64_t i = 0; i < n; i++) {
				uint64_t stamp = arflex_sys_now_ns();

				if (c == C_RAW_SHM) {
					atomic_store_explicit(&sh->stamp, stamp,
							      memory_order_relaxed);
					atomic_store_explicit(&sh->seq, ++raw_n,
							      memory_order_release);
				} else if ((r = arflex_state_write_at(p, &stamp, sizeof(stamp),
								      stamp))) {
					return r;
				}
				if ((r = spin_eq(&sh->ack, ++ack_n)))
					return r;
			}
		}
	}
	return 0;
}

/* Runs the round-trip schedule as the requester; @out[0] raw-mq, @out[1] mailbox. */
static int parent_round_trip(const struct opts *o, struct shared *sh, mqd_t tx, mqd_t rx,
			     struct arflex_mailbox *mb, uint64_t *out[2], uint64_t *seg,
			     int *failed)
{
	uint64_t rec[2] = { 0, 0 };
	uint32_t msg_seq = 0;
	char buf[MQ_MSG];

	memset(buf, 0x5a, sizeof(buf));
	for (unsigned round = 0; round <= o->rounds; round++) {
		for (int k = 0; k < 2; k++) {
			int c = seg_case(round, k, C_RAW_MQ, C_MAILBOX);
			uint64_t n = seg_count(o, round, o->n_mq);
			int r;

			*failed = c;
			if ((r = wait_phase(sh, ++*seg, c)))
				return r;
			for (uint64_t i = 0; i < n; i++) {
				uint64_t t0 = arflex_sys_now_ns(), t1;

				if (c == C_RAW_MQ) {
					struct timespec dl = arflex_sys_realtime_in(SPIN_TIMEOUT);

					if (mq_send(tx, buf, MQ_MSG, 0) != 0 ||
					    mq_timedreceive(rx, buf, sizeof(buf), NULL, &dl) != MQ_MSG)
						return -errno;
				} else {
					struct arflex_msg req, rsp;

					arflex_msg_init(&req, ARFLEX_CMD_PING, ++msg_seq);
					if ((r = arflex_mailbox_call(mb, &req, &rsp, SPIN_TIMEOUT)))
						return r;
				}
				t1 = arflex_sys_now_ns();
				if (round > 0)
					out[c == C_RAW_MQ ? 0 : 1][rec[c == C_RAW_MQ ? 0 : 1]++] =
						t1 - t0;
			}
		}
	}
	return 0;
}

/* Mean cost of one arflex_sys_now_ns() (CLOCK_MONOTONIC), for reading the figures: every
 * sample takes two, and a state-port write takes one more for the slot's stamp. */
static double clock_cost_ns(void)
{
	const unsigned n = 1000000;
	uint64_t t0 = arflex_sys_now_ns(), sink = 0;

	for (unsigned i = 0; i < n; i++)
		sink += arflex_sys_now_ns();
	return sink ? (double)(arflex_sys_now_ns() - t0) / n : 0.0;
}

/* ---- statistics and output ---------------------------------------------------------- */

struct stat5 {
	uint64_t n, min, p50, p99, p999, max;
	double mean;
};

static int cmp_u64(const void *a, const void *b)
{
	uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;

	return (x > y) - (x < y);
}

static uint64_t pct(const uint64_t *v, uint64_t n, double p)
{
	uint64_t rank = (uint64_t)ceil(p / 100.0 * (double)n);

	return v[(rank < 1 ? 1 : rank) - 1];
}

static struct stat5 stats_of(uint64_t *v, uint64_t n)
{
	struct stat5 s = { .n = n };
	double sum = 0;

	qsort(v, n, sizeof(*v), cmp_u64);
	for (uint64_t i = 0; i < n; i++)
		sum += (double)v[i];
	s.min = v[0];
	s.max = v[n - 1];
	s.p50 = pct(v, n, 50.0);
	s.p99 = pct(v, n, 99.0);
	s.p999 = pct(v, n, 99.9);
	s.mean = sum / (double)n;
	return s;
}

static void print_results(const struct opts *o, const struct stat5 *s, double r_port,
			  double r_mb, double clk)
{
	static const char *const kind[C_COUNT] = { "one-way", "one-way", "round trip",
						   "round trip" };

	printf("arflex-bench-ipc: writer/requester on CPU %d, reader/server on CPU %d, %s\n",
	       o->cpu_a, o->cpu_b, o->priority ? "SCHED_FIFO" : "SCHED_OTHER");
	printf("%-11s %-10s %8s %9s %9s %9s %9s %9s %9s\n", "case (ns)", "kind", "samples",
	       "min", "mean", "p50", "p99", "p99.9", "max");
	for (int c = 0; c < C_COUNT; c++)
		printf("%-11s %-10s %8" PRIu64 " %9" PRIu64 " %9.0f %9" PRIu64 " %9" PRIu64 " %9"
		       PRIu64 " %9" PRIu64 "\n", case_name[c], kind[c], s[c].n, s[c].min,
		       s[c].mean, s[c].p50, s[c].p99, s[c].p999, s[c].max);
	printf("state-port / raw-shm median: %.2fx (target <= %.1fx: %s)\n", r_port, TARGET_PORT,
	       r_port <= TARGET_PORT ? "met" : "NOT met");
	printf("mailbox / raw-mq median:     %.2fx (target <= %.1fx: %s)\n", r_mb, TARGET_MAILBOX,
	       r_mb <= TARGET_MAILBOX ? "met" : "NOT met");
	printf("(one CLOCK_MONOTONIC read costs %.1f ns here)\n", clk);
}

static int write_json(const struct opts *o, const struct stat5 *s, double r_port, double r_mb,
		      double clk)
{
	struct utsname u;
	FILE *f = fopen(o->json, "w");

	if (!f) {
		fprintf(stderr, "arflex-bench-ipc: --json %s: %s\n", o->json, strerror(errno));
		return -1;
	}
	if (uname(&u) != 0)
		memset(&u, 0, sizeof(u));
	fprintf(f, "{\n  \"tool\": \"arflex-bench-ipc\",\n  \"kernel\": \"%s %s\",\n", u.sysname,
		u.release);
	fprintf(f, "  \"cpus\": [%d, %d],\n  \"priority\": %d,\n  \"warmup\": %" PRIu64 ",\n",
		o->cpu_a, o->cpu_b, o->priority, o->warmup);
	fprintf(f, "  \"rounds\": %u,\n  \"clock_read_ns\": %.1f,\n", o->rounds, clk);
	fprintf(f, "  \"cases\": {\n");
	for (int c = 0; c < C_COUNT; c++)
		fprintf(f, "    \"%s\": {\"kind\": \"%s\", \"samples\": %" PRIu64 ", \"min_ns\": %"
			PRIu64 ", \"mean_ns\": %.1f, \"p50_ns\": %" PRIu64 ", \"p99_ns\": %" PRIu64
			", \"p99_9_ns\": %" PRIu64 ", \"max_ns\": %" PRIu64 "}%s\n", case_name[c],
			c < C_RAW_MQ ? "one-way" : "round-trip", s[c].n, s[c].min, s[c].mean,
			s[c].p50, s[c].p99, s[c].p999, s[c].max, c + 1 < C_COUNT ? "," : "");
	fprintf(f, "  },\n  \"ratios\": {\n");
	fprintf(f, "    \"state_port_over_raw_shm_p50\": {\"value\": %.3f, \"target\": %.1f, "
		"\"met\": %s},\n", r_port, TARGET_PORT, r_port <= TARGET_PORT ? "true" : "false");
	fprintf(f, "    \"mailbox_over_raw_mq_p50\": {\"value\": %.3f, \"target\": %.1f, "
		"\"met\": %s}\n  }\n}\n", r_mb, TARGET_MAILBOX, r_mb <= TARGET_MAILBOX ? "true" : "false");
	if (fclose(f) != 0) {
		fprintf(stderr, "arflex-bench-ipc: --json %s: %s\n", o->json, strerror(errno));
		return -1;
	}
	return 0;
}

/* ---- main --------------------------------------------------------------------------- */

static int create_raw_mq(char *name, const char *rid, const char *ch, mqd_t *q)
{
	struct mq_attr a = { .mq_maxmsg = ARFLEX_MQ_MAXMSG, .mq_msgsize = MQ_MSG };
	int r = arflex_ctl_obj_name(name, ARFLEX_OBJ_NAME_SIZE, rid, "raw", ch);

	if (r)
		return r;
	r = arflex_sys_mq_open(q, name, O_CREAT | O_EXCL | O_RDWR, 0600, &a);
	if (r)
		name[0] = 0; /* not ours: do not unlink */
	return r;
}

int main(int argc, char **argv)
{
	struct opts o;
	char rid[ARFLEX_ID_MAX + 1];
	struct shared *sh = MAP_FAILED;
	uint64_t *samples = MAP_FAILED; /* shared: the child writes the one-way samples */
	uint64_t *mq_samples[2] = { NULL, NULL };
	size_t samples_len = 0;
	struct arflex_port port;
	bool port_ok = false, mb_ok = false;
	struct arflex_mailbox mb;
	mqd_t mq_a = (mqd_t)-1, mq_b = (mqd_t)-1;
	struct stat5 st[C_COUNT];
	double r_port, r_mb, clk;
	int fd = -1, r, status, ret = 1, cur = 0;
	uint64_t seg = 0;
	struct sigaction sa;

	r = parse_args(argc, argv, &o);
	if (r)
		return r == 1 ? 0 : 2;
	memset(&sa, 0, sizeof(sa));
	sa.sa_handler = on_signal;
	sigemptyset(&sa.sa_mask);
	sigaction(SIGINT, &sa, NULL);
	sigaction(SIGTERM, &sa, NULL);
	sigaction(SIGHUP, &sa, NULL);

	snprintf(rid, sizeof(rid), "bench-%ld", (long)getpid());
	/* raw segment */
	if ((r = arflex_ctl_obj_name(raw_name, sizeof(raw_name), rid, "raw", "shm")))
		goto out_err;
	fd = arflex_sys_shm_open(raw_name, O_CREAT | O_EXCL | O_RDWR, 0600);
	if (fd < 0) {
		r = fd;
		raw_name[0] = 0;
		goto out_err;
	}
	if ((r = arflex_sys_ftruncate(fd, 4096)) ||
	    (r = arflex_sys_mmap((void **)&sh, 4096, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0)))
		goto out_err;
	arflex_sys_close(fd);
	fd = -1;
	/* one-way samples of the child (anonymous shared mapping, inherited by fork) */
	samples_len = 2 * o.n_port * sizeof(uint64_t);
	if ((r = arflex_sys_mmap((void **)&samples, samples_len, PROT_READ | PROT_WRITE,
				 MAP_SHARED | MAP_ANONYMOUS, -1, 0)))
		goto out_err;
	mq_samples[0] = calloc(o.n_mq, sizeof(uint64_t));
	mq_samples[1] = calloc(o.n_mq, sizeof(uint64_t));
	if (!mq_samples[0] || !mq_samples[1]) {
		r = -ENOMEM;
		goto out_err;
	}
	/* state port, created as a manager would */
	{
		struct arflex_port_spec spec = {
			.method = ARFLEX_PORT_STATE,
			.type = { .name = "bench.Stamp", .major = 1, .minor = 0,
				  .elem_size = sizeof(uint64_t) },
			.depth = 1,
		};

		if ((r = arflex_ctl_obj_name(port_name, sizeof(port_name), rid, "writer",
					     "out.t")))
			goto out_err;
		r = arflex_port_create(&port, port_name, &spec);
		if (r) {
			port_name[0] = 0;
			goto out_err;
		}
		port_ok = true;
	}
	/* raw queues and the mailbox */
	if ((r = create_raw_mq(mq_a_name, rid, "a", &mq_a)) ||
	    (r = create_raw_mq(mq_b_name, rid, "b", &mq_b)))
		goto out_err;
	arflex_ctl_obj_name(mb_cmd_name, sizeof(mb_cmd_name), rid, "mbox", "cmd");
	arflex_ctl_obj_name(mb_rsp_name, sizeof(mb_rsp_name), rid, "mbox", "rsp");
	r = arflex_mailbox_create(&mb, rid, "mbox");
	if (r) {
		mb_cmd_name[0] = mb_rsp_name[0] = 0;
		goto out_err;
	}
	mb_ok = true;

	fflush(NULL);
	child_pid = fork();
	if (child_pid < 0) {
		r = -errno;
		goto out_err;
	}
	if (child_pid == 0)
		child_main(&o, sh, samples, rid, mq_a, mq_b);
	setup_cpu(o.cpu_a, o.priority, "writer");

	if ((r = parent_one_way(&o, sh, &port, &seg, &cur)) ||
	    (r = parent_round_trip(&o, sh, mq_a, mq_b, &mb, mq_samples, &seg, &cur)))
		goto out_case;
	if (waitpid(child_pid, &status, 0) == child_pid)
		child_pid = 0;
	if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
		r = (int)atomic_load(&sh->child_error);
		fprintf(stderr, "arflex-bench-ipc: the reader process failed (%s)\n",
			strerror(r < 0 ? -r : EIO));
		goto out_err;
	}
	if (o.priority > 0)
		arflex_sys_set_sched(SCHED_OTHER, 0);

	st[C_RAW_SHM] = stats_of(samples, o.n_port);
	st[C_STATE_PORT] = stats_of(samples + o.n_port, o.n_port);
	st[C_RAW_MQ] = stats_of(mq_samples[0], o.n_mq);
	st[C_MAILBOX] = stats_of(mq_samples[1], o.n_mq);
	r_port = (double)st[C_STATE_PORT].p50 / (double)st[C_RAW_SHM].p50;
	r_mb = (double)st[C_MAILBOX].p50 / (double)st[C_RAW_MQ].p50;
	clk = clock_cost_ns();
	print_results(&o, st, r_port, r_mb, clk);
	ret = write_json(&o, st, r_port, r_mb, clk) == 0 ? 0 : 1;
	if (ret == 0)
		printf("JSON: %s\n", o.json);
	goto out;

out_case:
	{
		int ce = (int)atomic_load(&sh->child_error);

		fprintf(stderr, "arflex-bench-ipc: case %s failed: %s%s%s\n", case_name[cur],
			strerror(-r),
			ce ? "; reader: " : "", ce ? strerror(-ce) : "");
	}
	goto out;
out_err:
	fprintf(stderr, "arflex-bench-ipc: set-up failed: %s\n", strerror(-r));
out:
	if (child_pid > 0) {
		kill(child_pid, SIGKILL);
		waitpid(child_pid, NULL, 0);
		child_pid = 0;
	}
	if (mb_ok)
		arflex_mailbox_deinit(&mb); /* owner: closes and unlinks cmd/rsp */
	if (mq_a != (mqd_t)-1)
		arflex_sys_mq_close(mq_a);
	if (mq_b != (mqd_t)-1)
		arflex_sys_mq_close(mq_b);
	if (port_ok)
		arflex_port_destroy(&port);
	if (fd >= 0)
		arflex_sys_close(fd);
	if (sh != MAP_FAILED)
		arflex_sys_munmap(sh, 4096);
	if (samples != MAP_FAILED)
		arflex_sys_munmap(samples, samples_len);
	free(mq_samples[0]);
	free(mq_samples[1]);
	remove_objects(); /* whatever is left (idempotent) */
	if (!objects_gone())
		ret = 1;
	return ret;
}
