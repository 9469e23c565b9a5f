/* arflex_component_main: the template of an RT half (see arflex/component.h): arguments, the
 * control block, the mailbox, the task, the configure hook, then the mailbox thread's loop
 * (commands.c) until the end, and the exit. The RT thread is rt.c's, the ports ports.c's. */
#include "arflex/component.h"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

extern char **environ;

#include "internal.h"

static volatile sig_atomic_t got_signal;

static void on_signal(int sig)
{
	got_signal = sig;
}

/* One line, one write: stderr may be a non-blocking pipe (a line is dropped, never split or
 * waited for) or a pipe nobody reads any more (EPIPE, SIGPIPE is ignored). */
void arflex_comp_log(const struct arflex_component *c, const char *fmt, ...)
{
	char line[512];
	va_list ap;
	int n;

	n = snprintf(line, sizeof(line), "arflex: %s[%s.%s]: ", c->name, c->rid[0] ? c->rid : "?",
		     c->inst[0] ? c->inst : "?");
	if (n < 0 || (size_t)n >= sizeof(line) - 1)
		n = 0;
	va_start(ap, fmt);
	vsnprintf(line + n, sizeof(line) - 1 - (size_t)n, fmt, ap);
	va_end(ap);
	n = (int)strlen(line);
	line[n++] = '\n';
	fwrite(line, 1, (size_t)n, stderr);
	fflush(stderr);
	clearerr(stderr);
}

/* ---- main ----------------------------------------------------------------------------- */

static void usage(FILE *f, const char *exe)
{
	fprintf(f,
		"usage: %s --runtime <runtime-id> --instance <instance> [--help] [--version]\n"
		"  The RT half of an ARFLEX component. Started by the runtime (DRCR) after it\n"
		"  created /arflex.<runtime-id>.<instance>.{ctl,cmd,rsp} and the output ports;\n"
		"  ids match [a-z0-9-]{1,40}. Exit codes: 0 ok, 2 usage, 3 attach, 4 configure,\n"
		"  5 runtime error.\n",
		exe);
}

static int parse_args(struct arflex_component *c, int argc, char **argv)
{
	const char *exe = argc > 0 ? argv[0] : "arflex-component";

	for (int i = 1; i < argc; i++) {
		const char *a = argv[i];
		char *dst = NULL;

		if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
			usage(stdout, exe);
			return 1;
		}
		if (!strcmp(a, "--version")) {
			printf("%s: arflex rt-core ABI %u.%u\n", c->name, ARFLEX_ABI_MAJOR,
			       ARFLEX_ABI_MINOR);
			return 1;
		}
		if (!strcmp(a, "--runtime"))
			dst = c->rid;
		else if (!strcmp(a, "--instance"))
			dst = c->inst;
		if (!dst) {
			fprintf(stderr, "%s: unknown argument '%s' (argument %d)\n", exe, a, i);
			usage(stderr, exe);
			return -EINVAL;
		}
		if (i + 1 >= argc) {
			fprintf(stderr, "%s: %s needs a value\n", exe, a);
			return -EINVAL;
		}
		if (!arflex_ctl_id_valid(argv[i + 1])) {
			fprintf(stderr, "%s: %s '%s' is not [a-z0-9-]{1,40}\n", exe, a, argv[i + 1]);
			return -EINVAL;
		}
		strcpy(dst, argv[++i]);
	}
	if (!c->rid[0] || !c->inst[0]) {
		fprintf(stderr, "%s: --runtime and --instance are required\n", exe);
		usage(stderr, exe);
		return -EINVAL;
	}
	return 0;
}

static int attach_ctl(struct arflex_component *c)
{
	struct stat st;
	void *base;
	int fd, r;

	r = arflex_ctl_obj_name(c->ctl_name, sizeof(c->ctl_name), c->rid, c->inst, "ctl");
	if (r)
		return r;
	fd = arflex_sys_shm_open(c->ctl_name, O_RDWR, 0);
	if (fd < 0)
		return fd;
	r = arflex_sys_fstat(fd, &st);
	if (r)
		goto out_close;
	if ((size_t)st.st_size != ARFLEX_CTL_SIZE) {
		r = -EMSGSIZE;
		goto out_close;
	}
	r = arflex_sys_mmap(&base, ARFLEX_CTL_SIZE, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
	if (r)
		goto out_close;
	r = arflex_ctl_check(base, ARFLEX_CTL_SIZE);
	if (r)
		goto out_unmap;
	arflex_sys_close(fd);
	c->ctl = base;
	return 0;

out_unmap:
	arflex_sys_munmap(base, ARFLEX_CTL_SIZE);
out_close:
	arflex_sys_close(fd);
	return r;
}

static void init_params(struct arflex_ctl *ctl)
{
	for (unsigned i = 0; i < ctl->config.param_count; i++) {
		struct arflex_param_slot *s = &ctl->params[i];

		STORE(&s->applied_value, s->default_bits);
		STORE(&s->applied_status, 0);
		STORE(&s->applied_seq, 0);
	}
	/* a request left by the manager (e.g. before a restart) is applied now */
	arflex_ctl_param_apply_all(ctl, false);
}

/* The test fault of START (D58, as ARFLEX_FAULT_NTH in sys.c): ARFLEX_FAULT_START_ERRNO=<n>,
 * 1..4095, makes this half refuse every START with -n. Only the update tests' deliberately
 * faulty versions set it (a script that execs the real executable); nothing shipped does. */
static void fault_start_env(struct arflex_component *c)
{
	const char *s = arflex_sys_fault_env("ARFLEX_FAULT_START_ERRNO");
	char *end;
	long n;

	if (!s || !*s)
		return;
	n = strtol(s, &end, 10);
	if (*end || n < 1 || n > 4095) {
		fprintf(stderr, "arflex: %s: ARFLEX_FAULT_START_ERRNO=%s ignored (an errno 1..4095)\n",
			c->name, s);
		return;
	}
	c->fault_start_err = (int)n;
	fprintf(stderr, "arflex: %s: test fault: every START is refused with errno %ld\n", c->name, n);
}

/* A test fault's count from the environment variable @var: 1..10^9, else 0 (unset, or said
 * ignored on stderr). */
static uint64_t fault_count_env(const struct arflex_component *c, const char *var)
{
	const char *s = arflex_sys_fault_env(var);
	char *end;
	long long n;

	if (!s || !*s)
		return 0;
	n = strtoll(s, &end, 10);
	if (*end || n < 1 || n > 1000000000LL) {
		fprintf(stderr, "arflex: %s: %s=%s ignored (a count 1..10^9)\n", c->name, var, s);
		return 0;
	}
	return (uint64_t)n;
}

/* The test fault of a crash counted in cycles (D68): ARFLEX_FAULT_CRASH_AFTER_CYCLES=<n>,
 * 1..10^9, makes the RT thread raise SIGSEGV in its n-th update after each START, whatever the
 * time its spawn, READY and START took (a crash "a fixed time after the spawn" fell before the
 * START or the switch on a loaded machine). Only the update tests' deliberately faulty versions
 * set it; nothing shipped does. */
static void fault_crash_env(struct arflex_component *c)
{
	c->fault_crash_after = fault_count_env(c, "ARFLEX_FAULT_CRASH_AFTER_CYCLES");
	if (c->fault_crash_after)
		fprintf(stderr, "arflex: %s: test fault: SIGSEGV in update %llu after each START\n", c->name,
			(unsigned long long)c->fault_crash_after);
}

/* The test fault of a late cycle (D73): ARFLEX_FAULT_LATE_EVERY_CYCLES=<n>, 1..10^9, makes every
 * n-th update after each START spin until 100 us past the next release: one late cycle (an
 * overrun and a missed deadline) every n cycles, as a version too slow now and then would be.
 * Only the update tests' deliberately late versions set it; nothing shipped does. */
static void fault_late_env(struct arflex_component *c)
{
	c->fault_late_every = fault_count_env(c, "ARFLEX_FAULT_LATE_EVERY_CYCLES");
	if (c->fault_late_every)
		fprintf(stderr, "arflex: %s: test fault: every %llu-th update after each START ends late\n",
			c->name, (unsigned long long)c->fault_late_every);
}

/* Says once, at start, that ARFLEX_FAULT_* variables were found and ignored: without the
 * test-hook marker (ARFLEX_TEST_HOOKS=1, set only by a test runtime's DRCR and the tests: D80)
 * a half has no fault mode, whatever its environment holds. */
static void fault_ignored_note(const struct arflex_component *c)
{
	if (arflex_sys_test_hooks())
		return;
	for (char **e = environ; *e; e++)
		if (!strncmp(*e, "ARFLEX_FAULT_", 13)) {
			fprintf(stderr, "arflex: %s: ARFLEX_FAULT_* ignored: rt-core's test faults need "
				"ARFLEX_TEST_HOOKS=1, which only a test runtime sets\n", c->name);
			return;
		}
}

int arflex_component_main(int argc, char **argv, const struct arflex_component_ops *ops)
{
	static struct arflex_component comp;
	struct arflex_component *c = &comp;
	struct arflex_task_opts to;
	struct sigaction sa;
	unsigned noutputs;
	int r, code = ARFLEX_EXIT_OK;

	memset(c, 0, sizeof(*c));
	c->ops = ops;
	c->name = ops && ops->name ? ops->name : "component";
	c->mb.tx = c->mb.rx = (mqd_t)-1;
	if (!ops || !ops->update) {
		fprintf(stderr, "arflex: %s: ops->update is required\n", c->name);
		return ARFLEX_EXIT_USAGE;
	}
	r = parse_args(c, argc, argv);
	if (r)
		return r > 0 ? ARFLEX_EXIT_OK : ARFLEX_EXIT_USAGE;
	fault_start_env(c);
	fault_crash_env(c);
	fault_late_env(c);
	fault_ignored_note(c);

	memset(&sa, 0, sizeof(sa));
	sa.sa_handler = on_signal;
	sigemptyset(&sa.sa_mask);
	sigaction(SIGTERM, &sa, NULL);
	sigaction(SIGINT, &sa, NULL);
	/* the supervisor's death must never kill us: no SIGPIPE, logging never blocks */
	sa.sa_handler = SIG_IGN;
	sigaction(SIGPIPE, &sa, NULL);
	arflex_sys_nonblock_pipe(1);
	arflex_sys_nonblock_pipe(2);

	r = attach_ctl(c);
	if (r) {
		arflex_comp_log(c, "cannot attach control block %s: %s", c->ctl_name, strerror(-r));
		return ARFLEX_EXIT_ATTACH;
	}
	STORE(&c->ctl->pid, (int32_t)getpid());
	STORE(&c->ctl->exit_status, 0);
	STORE(&c->ctl->hold, 0);
	/* a restart reuses the block: keep only the manager's reset-required bit */
	__atomic_and_fetch(&c->ctl->flags, (uint32_t)ARFLEX_FLAG_RESET_REQUIRED, __ATOMIC_ACQ_REL);
	for (unsigned k = 0; k < ARFLEX_WARN_KINDS; k++)
		STORE(&c->ctl->warnings[k], 0);
	STORE(&c->ctl->state, ARFLEX_STATE_CONFIGURING);
	init_params(c->ctl);
	r = arflex_mailbox_attach(&c->mb, c->rid, c->inst);
	if (r) {
		arflex_comp_log(c, "cannot open queues /arflex.%s.%s.{cmd,rsp}: %s", c->rid, c->inst,
		      strerror(-r));
		code = ARFLEX_EXIT_ATTACH;
		goto out_failed;
	}
	if (c->ctl->config.cfg_flags & ARFLEX_CFG_SUPERVISOR_PIPE) {
		r = arflex_comp_read_token(c);
		if (r) {
			arflex_comp_log(c, "no mailbox token from the manager on the supervisor pipe "
					"(fd 0): %s", strerror(-r));
			code = ARFLEX_EXIT_ATTACH;
			goto out_mailbox;
		}
		r = arflex_comp_watch_start(c);
		if (r) {
			arflex_comp_log(c, "cannot start the supervisor-pipe watcher: %s", strerror(-r));
			code = ARFLEX_EXIT_ATTACH;
			goto out_mailbox;
		}
	}

	memset(&to, 0, sizeof(to));
	to.period_ns = c->ctl->config.period_ns;
	to.deadline_ns = c->ctl->config.deadline_ns;
	to.priority = c->ctl->config.priority;
	to.cpu_mask = c->ctl->config.cpu_mask;
	to.no_mlock = c->ctl->config.cfg_flags & ARFLEX_CFG_NO_MLOCK;
	to.no_dma_latency = c->ctl->config.cfg_flags & ARFLEX_CFG_NO_DMA_LATENCY;
	to.cycle = arflex_comp_rt_cycle;
	to.on_start = arflex_comp_rt_start;
	to.on_stop = arflex_comp_rt_stop;
	to.arg = c;
	to.stats = &c->ctl->stats;
	to.warnings = c->ctl->warnings;
	to.flags = &c->ctl->flags;
	to.name = c->name;
	r = arflex_task_init(&c->task, &to);
	if (r) {
		arflex_comp_log(c, "invalid timing in the control block (period %llu ns, deadline %llu ns, "
		      "priority %d)", (unsigned long long)to.period_ns,
		      (unsigned long long)to.deadline_ns, to.priority);
		code = ARFLEX_EXIT_CONFIGURE;
		goto out_mailbox;
	}

	c->configuring = true;
	r = ops->configure ? ops->configure(c, ops->user) : 0;
	c->configuring = false;
	if (r) {
		arflex_comp_log(c, "configure failed: %s", strerror(r < 0 ? -r : r));
		code = ARFLEX_EXIT_CONFIGURE;
		goto out_task;
	}
	/* A sporadic task is clocked by its first declared input (D27); without any input
	 * nothing can release it, and it keeps the periodic loop at its minimum inter-arrival. */
	if (c->ctl->config.task_type == ARFLEX_TASK_SPORADIC && c->ninputs > 0) {
		c->sporadic = true;
		c->task.o.poll = arflex_comp_rt_poll;
		c->task.o.poll_ns = ARFLEX_TASK_POLL_NS(c->task.o.period_ns);
	}
	arflex_comp_readopt_advertise(c);
	STORE(&c->ctl->state, ARFLEX_STATE_READY);

	arflex_comp_serve_loop(c, &got_signal);

	if (c->running)
		arflex_comp_stop(c);
	if (ops->cleanup)
		ops->cleanup(c, ops->user);
	noutputs = c->noutputs;
	arflex_comp_close_ports(c);
	arflex_comp_state_close(c);
	arflex_task_report(&c->task, stderr);
	arflex_task_deinit(&c->task);
	arflex_mailbox_deinit(&c->mb);
	STORE(&c->ctl->state, ARFLEX_STATE_EXITED);
	arflex_comp_watch_stop(c);
	if (c->orphaned)
		arflex_comp_unlink_own(c, noutputs);
	arflex_sys_munmap(c->ctl, ARFLEX_CTL_SIZE);
	return ARFLEX_EXIT_OK;

out_task:
	arflex_comp_close_ports(c);
	arflex_comp_state_close(c);
	arflex_task_deinit(&c->task);
out_mailbox:
	arflex_mailbox_deinit(&c->mb);
out_failed:
	STORE(&c->ctl->exit_status, r < 0 ? r : -EINVAL);
	STORE(&c->ctl->state, ARFLEX_STATE_FAILED);
	arflex_comp_watch_stop(c);
	arflex_sys_munmap(c->ctl, ARFLEX_CTL_SIZE);
	return code;
}
