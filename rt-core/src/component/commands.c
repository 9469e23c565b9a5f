/* The mailbox thread of an RT half (the main thread after configure): serves the manager's
 * commands (ABI.md 5) until SHUTDOWN, a signal or the orphan policy ends it; a request with a
 * wrong token is counted and ignored (D13). */
#include "arflex/component.h"

#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>

#include "internal.h"

#define POLL_NS 100000000u          /* mailbox thread wakes at least every 100 ms */
#define APPLY_WAIT_NS 1000000000u   /* SET_PARAM/BIND wait for the cycle boundary */

void arflex_comp_wait_short(void)
{
	arflex_sys_sleep_until(arflex_sys_now_ns() + 200000u);
}

uint64_t arflex_comp_apply_deadline(const struct arflex_component *c)
{
	return arflex_sys_now_ns() + APPLY_WAIT_NS + 2 * c->ctl->config.period_ns;
}

static int do_start(struct arflex_component *c)
{
	sigset_t all, old;
	int r;

	if (c->running)
		return -EALREADY;
	if (c->fault_start_err) { /* a test fault only (D58): never set by a shipped default */
		arflex_comp_log(c, "START refused: test fault ARFLEX_FAULT_START_ERRNO=%d (%s)",
				c->fault_start_err, strerror(c->fault_start_err));
		arflex_comp_adopt_done(c); /* an ADOPT given for it is not taken */
		return -c->fault_start_err;
	}
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

int arflex_comp_stop(struct arflex_component *c)
{
	if (!c->running)
		return -EALREADY;
	STORE(&c->ctl->state, ARFLEX_STATE_STOPPING);
	arflex_task_stop(&c->task);
	c->running = false;
	arflex_comp_retire_bindings(c);
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
	deadline = arflex_comp_apply_deadline(c);
	while (LOAD(&s->applied_seq) != seq) {
		if (arflex_sys_now_ns() > deadline)
			return -ETIMEDOUT;
		arflex_comp_wait_short();
	}
	fill_param(c, (unsigned)idx, &m->u.param);
	m->payload_len = sizeof(m->u.param);
	return LOAD(&s->applied_status);
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
		st = arflex_comp_stop(c);
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
		st = arflex_comp_bind_cmd(c, m);
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
	case ARFLEX_CMD_READOPT:
		st = c->running ? arflex_comp_readopt_cmd(c, m) : -ENOTCONN; /* not started: ADOPT */
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

void arflex_comp_serve_loop(struct arflex_component *c, const volatile sig_atomic_t *signaled)
{
	struct arflex_msg m;

	while (!*signaled) {
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
			arflex_comp_wait_short();
			continue;
		}
		if ((m.flags & ARFLEX_MSG_REPLY) || forged(c, &m))
			continue;
		if (serve(c, &m))
			break;
	}
}
