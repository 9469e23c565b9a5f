/* arflex_component_main: the template of an RT half (see arflex/component.h). */
#include "arflex/component.h"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include "internal.h"

#define POLL_NS 100000000u          /* mailbox thread wakes at least every 100 ms */
#define APPLY_WAIT_NS 1000000000u   /* SET_PARAM/BIND wait for the cycle boundary */

static struct arflex_port unbind_marker;
static volatile sig_atomic_t got_signal;

static void on_signal(int sig)
{
	got_signal = sig;
}

#include <stdarg.h>
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

/* ---- port declaration (configure) ---------------------------------------------------- */

int arflex_component_output(struct arflex_component *c, const char *port,
			    enum arflex_port_method method, const struct arflex_port_type *type,
			    struct arflex_port **out)
{
	char chan[ARFLEX_NAME_SIZE + 8], name[ARFLEX_OBJ_NAME_SIZE];
	int r;

	if (!c->configuring || !arflex_port_name_valid(port) || !type || !type->name)
		return -EINVAL;
	for (unsigned i = 0; i < c->noutputs; i++)
		if (!strcmp(c->output_names[i], port))
			return -EEXIST;
	if (c->noutputs >= ARFLEX_MAX_OUTPUTS)
		return -ENOSPC;
	snprintf(chan, sizeof(chan), "out.%s", port);
	r = arflex_ctl_obj_name(name, sizeof(name), c->rid, c->inst, chan);
	if (r)
		return r;
	r = arflex_port_open(&c->outputs[c->noutputs], name, true, true, method, type);
	if (r) {
		arflex_comp_log(c, "output port '%s' (%s): %s", port, name, strerror(-r));
		return r;
	}
	snprintf(c->output_names[c->noutputs], ARFLEX_NAME_SIZE, "%s", port);
	*out = &c->outputs[c->noutputs++];
	return 0;
}

int arflex_component_input(struct arflex_component *c, const char *port,
			   enum arflex_port_method method, const struct arflex_port_type *type,
			   struct arflex_input **out)
{
	struct arflex_input *in;

	if (!c->configuring || !arflex_port_name_valid(port) || !type || !type->name ||
	    strlen(type->name) >= ARFLEX_TYPE_NAME_SIZE || method < ARFLEX_PORT_STATE ||
	    method > ARFLEX_PORT_FRAME)
		return -EINVAL;
	for (unsigned i = 0; i < c->ninputs; i++)
		if (!strcmp(c->inputs[i].name, port))
			return -EEXIST;
	if (c->ninputs >= ARFLEX_MAX_INPUTS)
		return -ENOSPC;
	in = &c->inputs[c->ninputs++];
	memset(in, 0, sizeof(*in));
	snprintf(in->name, sizeof(in->name), "%s", port);
	snprintf(in->type_name, sizeof(in->type_name), "%s", type->name);
	in->type = *type;
	in->type.name = in->type_name;
	in->method = method;
	in->warnings = c->ctl->warnings;
	if (c->ninputs <= ARFLEX_CTL_INPUTS) {
		in->count = &c->ctl->inputs[c->ninputs - 1];
		STORE(&in->count->rejects, 0);
		STORE(&in->count->name_hash, (uint32_t)arflex_port_type_hash(port));
	}
	*out = in;
	return 0;
}

static void close_binding(struct arflex_port *p)
{
	if (p && p != &unbind_marker) {
		arflex_port_close(p);
		free(p);
	}
}

static void close_ports(struct arflex_component *c)
{
	for (unsigned i = 0; i < c->ninputs; i++) {
		struct arflex_input *in = &c->inputs[i];

		close_binding(in->cur);
		close_binding(in->pending);
		close_binding(in->retired);
		in->cur = in->pending = in->retired = NULL;
	}
	c->ninputs = 0;
	for (unsigned i = 0; i < c->noutputs; i++)
		arflex_port_close(&c->outputs[i]);
	c->noutputs = 0;
}

/* ---- the RT thread ---------------------------------------------------------------------- */

static void take_bindings(struct arflex_component *c)
{
	for (unsigned i = 0; i < c->ninputs; i++) {
		struct arflex_input *in = &c->inputs[i];
		struct arflex_port *p;

		if (!LOAD(&in->pending))
			continue;
		p = XCHG(&in->pending, NULL);
		if (!p)
			continue;
		STORE(&in->retired, in->cur);
		in->cur = p == &unbind_marker ? NULL : p;
		if (in->cur)
			in->binding++;
		STORE(&in->done_seq, LOAD(&in->pend_seq));
	}
}

/* Safe mode when the runtime heartbeat is stale (judged over the RT thread's own cycling time,
 * arflex_hb_judge) or the supervisor is lost (the watcher saw EOF on fd 0): within one cycle. */
static void check_heartbeat(struct arflex_component *c, uint64_t now)
{
	struct arflex_ctl *ctl = c->ctl;
	bool stale, want;

	stale = arflex_hb_judge(&c->hbw, LOAD(&ctl->runtime_hb_ns), now, ctl->config.period_ns,
				ctl->config.hb_timeout_ns);
	STORE(&c->hb_stale, stale);
	c->lost_seen = (LOAD(&ctl->flags) & ARFLEX_FLAG_SUPERVISOR_LOST) != 0;
	stale = stale || c->lost_seen;
	if (stale && (ctl->config.cfg_flags & ARFLEX_CFG_MOVES_HARDWARE) &&
	    !(LOAD(&ctl->flags) & ARFLEX_FLAG_RESET_REQUIRED))
		__atomic_or_fetch(&ctl->flags, ARFLEX_FLAG_RESET_REQUIRED, __ATOMIC_RELEASE);
	want = stale || (LOAD(&ctl->flags) & ARFLEX_FLAG_RESET_REQUIRED);
	if (want && !c->safe) {
		c->safe = true;
		c->safe_first = true;
		__atomic_or_fetch(&ctl->flags, ARFLEX_FLAG_SAFE_ACTIVE, __ATOMIC_RELEASE);
		__atomic_add_fetch(&ctl->warnings[ARFLEX_WARN_SAFE], 1, __ATOMIC_RELAXED);
	} else if (!want && c->safe) {
		c->safe = false;
		__atomic_and_fetch(&ctl->flags, ~(uint32_t)ARFLEX_FLAG_SAFE_ACTIVE,
				   __ATOMIC_RELEASE);
	}
}

/* The work of every cycle boundary: own heartbeat, bindings, parameter requests, the runtime
 * heartbeat (safe mode). */
static void rt_boundary(struct arflex_component *c, uint64_t now)
{
	struct arflex_ctl *ctl = c->ctl;

	STORE(&ctl->rt_hb_ns, now);
	take_bindings(c);
	if (arflex_ctl_param_apply_all(ctl, true))
		for (unsigned i = 0; i < ctl->config.param_count; i++)
			if (LOAD(&ctl->params[i].applied_seq) ==
				    LOAD(&ctl->params[i].req_seq) &&
			    ctl->params[i].applied_status)
				__atomic_add_fetch(&ctl->warnings[ARFLEX_WARN_PARAM], 1,
						   __ATOMIC_RELAXED);
	check_heartbeat(c, now);
}

/* Sporadic release test (D27), at every poll tick of the RT thread: the poll is a cycle
 * boundary (heartbeat, bindings, parameters, safe mode are kept up while no sample comes). The
 * clock is inputs[0], the first declared input: a release per change of its provider's write
 * count (hdr->head: values written, state, or elements published, stream and frame). At START
 * and on each new binding a value already published counts as one new sample. While safe mode
 * is active the task is released every period (the safe hook does not wait for input) and the
 * samples are consumed without an update. */
static int rt_poll(void *arg, uint64_t now, uint64_t *events)
{
	struct arflex_component *c = arg;
	struct arflex_input *in = &c->inputs[0];
	uint64_t head, n = 0;

	rt_boundary(c, now);
	if (in->cur) {
		if (in->binding != c->clk_binding) {
			c->clk_binding = in->binding;
			c->clk_seen = 0;
		}
		head = LOAD(&in->cur->hdr->head);
		/* a provider segment formatted anew restarts its count */
		n = head >= c->clk_seen ? head - c->clk_seen : head;
		c->clk_seen = head;
	}
	if (c->safe) {
		*events = 1;
		return 1;
	}
	*events = n;
	return n > 0;
}

static int rt_cycle(void *arg, uint64_t release_ns)
{
	struct arflex_component *c = arg;
	struct arflex_ctl *ctl = c->ctl;
	int r;

	if (!c->sporadic) /* sporadic: its poll, just now, was the boundary */
		rt_boundary(c, arflex_sys_now_ns());
	if (c->safe) {
		uint64_t seq = ctl->stats.seq;

		r = c->ops->safe ? c->ops->safe(c, c->ops->user,
						(enum arflex_safe_mode)ctl->config.safe_mode,
						c->safe_first)
				 : 0;
		c->safe_first = false;
		if (c->lost_seen)
			STORE(&c->orphan_safe, true);
		STORE(&ctl->stats.seq, seq + 1);
		__atomic_thread_fence(__ATOMIC_RELEASE);
		ctl->stats.safe_cycles++;
		STORE(&ctl->stats.seq, seq + 2);
	} else {
		r = c->ops->update(c, c->ops->user, release_ns);
	}
	return r < 0 ? r : 0;
}

static int rt_start(void *arg)
{
	struct arflex_component *c = arg;
	int r;

	c->safe = false;
	c->clk_binding = 0; /* the first poll takes the clock's binding as new */
	c->clk_seen = 0;
	memset(&c->hbw, 0, sizeof(c->hbw));
	take_bindings(c);
	check_heartbeat(c, arflex_sys_now_ns());
	r = c->ops->start ? c->ops->start(c, c->ops->user) : 0;
	return r < 0 ? r : arflex_comp_adopt_at_start(c); /* after start: it may reset state */
}

static int rt_stop(void *arg)
{
	struct arflex_component *c = arg;

	if (c->ops->stop)
		c->ops->stop(c, c->ops->user);
	return 0;
}

/* ---- the mailbox thread (main thread) -------------------------------------------------- */

static void wait_short(void)
{
	arflex_sys_sleep_until(arflex_sys_now_ns() + 200000u);
}

static int do_start(struct arflex_component *c)
{
	sigset_t all, old;
	int r;

	if (c->running)
		return -EALREADY;
	STORE(&c->ctl->state, ARFLEX_STATE_RUNNING);
	/* the RT thread must not take the process signals */
	sigemptyset(&all);
	sigaddset(&all, SIGTERM);
	sigaddset(&all, SIGINT);
	pthread_sigmask(SIG_BLOCK, &all, &old);
	r = arflex_task_start(&c->task);
	pthread_sigmask(SIG_SETMASK, &old, NULL);
	arflex_comp_adopt_done(c); /* the adopted state is the RT thread's now, or refused */
	if (r) {
		STORE(&c->ctl->state, ARFLEX_STATE_READY);
		return r;
	}
	c->running = true;
	return 0;
}

static int do_stop(struct arflex_component *c)
{
	if (!c->running)
		return -EALREADY;
	STORE(&c->ctl->state, ARFLEX_STATE_STOPPING);
	arflex_task_stop(&c->task);
	c->running = false;
	take_bindings(c); /* a binding posted at the very end */
	for (unsigned i = 0; i < c->ninputs; i++)
		close_binding(XCHG(&c->inputs[i].retired, NULL));
	STORE(&c->ctl->state, ARFLEX_STATE_READY);
	return 0;
}

static int resolve_param(struct arflex_component *c, struct arflex_msg_param *p)
{
	if (p->index == UINT32_MAX) {
		if (!memchr(p->name, 0, sizeof(p->name)))
			return -EINVAL;
		return arflex_ctl_param_find(c->ctl, p->name);
	}
	if (p->index >= c->ctl->config.param_count)
		return -ENOENT;
	return (int)p->index;
}

static void fill_param(struct arflex_component *c, unsigned idx, struct arflex_msg_param *p)
{
	struct arflex_param_slot *s = &c->ctl->params[idx];

	p->index = idx;
	p->type = s->type;
	p->value = LOAD(&s->applied_value);
	p->applied_seq = LOAD(&s->applied_seq);
	memcpy(p->name, s->name, sizeof(p->name));
}

static int do_set_param(struct arflex_component *c, struct arflex_msg *m)
{
	struct arflex_param_slot *s;
	uint64_t seq, deadline;
	int idx = resolve_param(c, &m->u.param), r;

	if (idx < 0)
		return idx;
	r = arflex_ctl_param_validate(c->ctl, (unsigned)idx, m->u.param.value, c->running);
	if (r)
		return r;
	s = &c->ctl->params[idx];
	seq = arflex_ctl_param_request(c->ctl, (unsigned)idx, m->u.param.value);
	if (!c->running)
		arflex_ctl_param_apply(c->ctl, (unsigned)idx, false);
	deadline = arflex_sys_now_ns() + APPLY_WAIT_NS + 2 * c->ctl->config.period_ns;
	while (LOAD(&s->applied_seq) != seq) {
		if (arflex_sys_now_ns() > deadline)
			return -ETIMEDOUT;
		wait_short();
	}
	fill_param(c, (unsigned)idx, &m->u.param);
	m->payload_len = sizeof(m->u.param);
	return LOAD(&s->applied_status);
}

static struct arflex_input *find_input(struct arflex_component *c, const char *port)
{
	for (unsigned i = 0; i < c->ninputs; i++)
		if (!strncmp(c->inputs[i].name, port, ARFLEX_NAME_SIZE))
			return &c->inputs[i];
	return NULL;
}

/* Hands @p (a new binding or &unbind_marker) to the RT thread, or swaps directly when it
 * does not run, then unmaps the replaced binding. */
static int post_binding(struct arflex_component *c, struct arflex_input *in,
			struct arflex_port *p)
{
	uint32_t seq;
	uint64_t deadline;

	if (!c->running) {
		close_binding(in->cur);
		in->cur = p == &unbind_marker ? NULL : p;
		if (in->cur)
			in->binding++;
		return 0;
	}
	seq = LOAD(&in->pend_seq) + 1;
	STORE(&in->pend_seq, seq);
	STORE(&in->pending, p);
	deadline = arflex_sys_now_ns() + APPLY_WAIT_NS + 2 * c->ctl->config.period_ns;
	while (LOAD(&in->done_seq) != seq) {
		if (arflex_sys_now_ns() > deadline) {
			struct arflex_port *back = XCHG(&in->pending, NULL);

			if (back == p) {
				close_binding(p);
				return -ETIMEDOUT;
			}
			deadline = UINT64_MAX; /* taken right now: done_seq follows */
		}
		wait_short();
	}
	close_binding(XCHG(&in->retired, NULL));
	return 0;
}

static int do_bind(struct arflex_component *c, struct arflex_msg *m)
{
	struct arflex_msg_bind *b = &m->u.bind;
	struct arflex_input *in;
	struct arflex_port *p;
	int r;

	if (!memchr(b->port, 0, sizeof(b->port)) || !memchr(b->shm_name, 0, sizeof(b->shm_name)))
		return -EINVAL;
	in = find_input(c, b->port);
	if (!in)
		return -ENOENT;
	if (m->cmd == ARFLEX_CMD_UNBIND) {
		if (!in->bound)
			return -ENOTCONN;
		r = post_binding(c, in, &unbind_marker);
		if (!r)
			in->bound = false;
		return r;
	}
	if (strncmp(b->shm_name, "/arflex.", 8))
		return -EINVAL;
	p = calloc(1, sizeof(*p));
	if (!p)
		return -ENOMEM;
	r = arflex_port_open(p, b->shm_name, in->method == ARFLEX_PORT_STREAM, false, in->method,
			     &in->type);
	if (r) {
		arflex_comp_log(c, "BIND %s to %s: %s", b->port, b->shm_name, strerror(-r));
		free(p);
		return r;
	}
	r = post_binding(c, in, p);
	if (!r)
		in->bound = true;
	return r;
}

static void fill_metric(const struct arflex_metric *m, struct arflex_msg_metric *o)
{
	o->min_ns = m->count ? m->min_ns : 0;
	o->max_ns = m->max_ns;
	o->mean_ns = m->count ? m->sum_ns / m->count : 0;
	o->mad_ns = m->count ? m->sum_absdev_ns / m->count : 0;
	o->p50_ns = arflex_metric_percentile(m, 50.0);
	o->p99_ns = arflex_metric_percentile(m, 99.0);
	o->p999_ns = arflex_metric_percentile(m, 99.9);
}

/* Serves one request; returns true when the process should shut down. */
static bool serve(struct arflex_component *c, struct arflex_msg *m)
{
	bool quit = false;
	int st;

	switch (m->cmd) {
	case ARFLEX_CMD_START:
		st = do_start(c);
		break;
	case ARFLEX_CMD_STOP:
		st = do_stop(c);
		break;
	case ARFLEX_CMD_SET_PARAM:
		st = do_set_param(c, m);
		break;
	case ARFLEX_CMD_GET_PARAM:
		st = resolve_param(c, &m->u.param);
		if (st >= 0) {
			fill_param(c, (unsigned)st, &m->u.param);
			m->payload_len = sizeof(m->u.param);
			st = 0;
		}
		break;
	case ARFLEX_CMD_BIND:
	case ARFLEX_CMD_UNBIND:
		st = do_bind(c, m);
		break;
	case ARFLEX_CMD_GET_STATE: {
		struct arflex_msg_state *s = &m->u.state;
		uint32_t bits = 0;

		for (unsigned i = 0; i < c->ninputs; i++)
			if (c->inputs[i].bound)
				bits |= 1u << i;
		memset(s, 0, sizeof(*s));
		s->state = arflex_ctl_state(c->ctl);
		s->flags = arflex_ctl_flags(c->ctl);
		s->pid = c->ctl->pid;
		s->bound_inputs = bits;
		s->cycles = LOAD(&c->ctl->stats.cycles);
		m->payload_len = sizeof(*s);
		st = 0;
		break;
	}
	case ARFLEX_CMD_GET_STATS: {
		struct arflex_msg_stats *o = &m->u.stats;

		st = arflex_ctl_stats_read(c->ctl, &c->stats_copy);
		if (!st) {
			memset(o, 0, sizeof(*o));
			o->cycles = c->stats_copy.cycles;
			o->overruns = c->stats_copy.overruns;
			o->deadline_misses = c->stats_copy.deadline_misses;
			o->update_errors = c->stats_copy.update_errors;
			fill_metric(&c->stats_copy.latency, &o->latency);
			fill_metric(&c->stats_copy.exec, &o->exec);
			m->payload_len = sizeof(*o);
		}
		break;
	}
	case ARFLEX_CMD_RESET: {
		uint64_t t = c->ctl->config.hb_timeout_ns, hb = LOAD(&c->ctl->runtime_hb_ns);
		uint64_t now = arflex_sys_now_ns();
		bool stale = t && now > hb && now - hb > t;

		/* While running, the heartbeat is judged as the RT thread does (over its own
		 * cycling time): an old heartbeat after a stall of the whole machine does not
		 * refuse a reset; a heartbeat fresh right now always allows it. */
		if (stale && c->running)
			stale = LOAD(&c->hb_stale);
		if (stale || (arflex_ctl_flags(c->ctl) & ARFLEX_FLAG_SUPERVISOR_LOST)) {
			st = -EAGAIN;
		} else if ((LOAD(&c->ctl->hold) & 0xffu) == ARFLEX_HOLD_SAFETY_INPUT) {
			st = -EBUSY; /* the cause persists: a safety input does not permit motion */
		} else {
			__atomic_and_fetch(&c->ctl->flags, ~(uint32_t)ARFLEX_FLAG_RESET_REQUIRED,
					   __ATOMIC_RELEASE);
			if (!c->running)
				__atomic_and_fetch(&c->ctl->flags,
						   ~(uint32_t)ARFLEX_FLAG_SAFE_ACTIVE,
						   __ATOMIC_RELEASE);
			st = 0;
		}
		break;
	}
	case ARFLEX_CMD_SHUTDOWN:
		quit = true;
		st = 0;
		break;
	case ARFLEX_CMD_PING:
		st = 0;
		break;
	case ARFLEX_CMD_ADOPT:
		st = c->running ? -EBUSY : arflex_comp_adopt_cmd(c, m);
		break;
	default:
		st = -ENOSYS;
		break;
	}
	if (m->cmd != ARFLEX_CMD_GET_PARAM && m->cmd != ARFLEX_CMD_SET_PARAM &&
	    m->cmd != ARFLEX_CMD_GET_STATE && m->cmd != ARFLEX_CMD_GET_STATS) {
		memset(&m->u, 0, sizeof(m->u));
		m->payload_len = 0;
	}
	m->flags = ARFLEX_MSG_REPLY;
	m->status = st;
	m->abi_major = ARFLEX_ABI_MAJOR;
	m->abi_minor = ARFLEX_ABI_MINOR;
	arflex_mailbox_send(&c->mb, m, POLL_NS);
	return quit;
}

#define FORGED_LOG_NS 1000000000u /* one log line per burst of forged requests */

/* A request with another token than the manager's is not from the manager (ABI.md 5,
 * DECISIONS.md D13): counted, logged at most once a second, never answered or acted on.
 * Returns true when @m is such a request. */
static bool forged(struct arflex_component *c, const struct arflex_msg *m)
{
	uint64_t now;

	if (m->token == c->token)
		return false;
	__atomic_add_fetch(&c->ctl->warnings[ARFLEX_WARN_FORGED], 1, __ATOMIC_RELAXED);
	c->forged_unlogged++;
	now = arflex_sys_now_ns();
	if (c->forged_log_ns && now - c->forged_log_ns < FORGED_LOG_NS)
		return true;
	arflex_comp_log(c, "ignored %llu mailbox request(s) with a wrong token (last: %s seq %u): "
			"not from my manager", (unsigned long long)c->forged_unlogged,
			arflex_cmd_name(m->cmd), m->seq);
	c->forged_unlogged = 0;
	c->forged_log_ns = now;
	return true;
}

static void serve_loop(struct arflex_component *c)
{
	struct arflex_msg m;

	while (!got_signal) {
		int r;

		if (arflex_comp_orphan_done(c)) {
			c->orphaned = true;
			break;
		}
		arflex_task_report(&c->task, stderr);
		if (!c->running)
			arflex_ctl_param_apply_all(c->ctl, false);
		r = arflex_mailbox_recv(&c->mb, &m, LOAD(&c->lost_ns) ? ARFLEX_ORPHAN_POLL_NS : POLL_NS);
		if (r == -ETIMEDOUT)
			continue;
		if (r == -EPROTO) {
			/* malformed: answer if it looks like ours at all, so callers do not hang */
			if (m.magic == ARFLEX_MSG_MAGIC && !forged(c, &m)) {
				m.flags = ARFLEX_MSG_REPLY;
				m.status = -EPROTO;
				memset(&m.u, 0, sizeof(m.u));
				arflex_mailbox_send(&c->mb, &m, POLL_NS);
			}
			continue;
		}
		if (r) {
			arflex_comp_log(c, "mailbox receive failed: %s", strerror(-r));
			wait_short();
			continue;
		}
		if ((m.flags & ARFLEX_MSG_REPLY) || forged(c, &m))
			continue;
		if (serve(c, &m))
			break;
	}
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
	to.cycle = rt_cycle;
	to.on_start = rt_start;
	to.on_stop = rt_stop;
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
		c->task.o.poll = rt_poll;
		c->task.o.poll_ns = ARFLEX_TASK_POLL_NS(c->task.o.period_ns);
	}
	STORE(&c->ctl->state, ARFLEX_STATE_READY);

	serve_loop(c);

	if (c->running)
		do_stop(c);
	if (ops->cleanup)
		ops->cleanup(c, ops->user);
	noutputs = c->noutputs;
	close_ports(c);
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
	close_ports(c);
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
