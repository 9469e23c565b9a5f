/* The RT thread of an RT half: the task's hooks (arflex/task.h) around the component's own.
 * Every cycle boundary keeps the half's heartbeat, takes new bindings and parameter requests,
 * and judges the runtime's heartbeat (safe mode); a cycle runs the update hook, or the safe
 * hook while safe mode is active. Never blocks, allocates or prints. */
#include "arflex/component.h"

#include <signal.h>
#include <string.h>

#include "internal.h"

/* Safe mode when the runtime heartbeat is stale (judged over the RT thread's own cycling time,
 * arflex_hb_judge) or the supervisor is lost (the watcher saw EOF on fd 0): within one cycle. */
static void check_heartbeat(struct arflex_component *c, uint64_t now)
{
	struct arflex_ctl *ctl = c->ctl;
	bool stale, want, hb_lost;

	stale = arflex_hb_judge(&c->hbw, LOAD(&ctl->runtime_hb_ns), now, ctl->config.period_ns,
				ctl->config.hb_timeout_ns);
	hb_lost = stale;
	if (stale && !LOAD(&c->hb_stale)) /* D75: each loss counted, so the log says the cause */
		__atomic_add_fetch(&ctl->warnings[ARFLEX_WARN_HB_LOST], 1, __ATOMIC_RELAXED);
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
		if (!hb_lost && !c->lost_seen) /* RESET_REQUIRED alone: a latch, not the heartbeat */
			__atomic_add_fetch(&ctl->warnings[ARFLEX_WARN_RESET], 1, __ATOMIC_RELAXED);
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
	arflex_comp_take_bindings(c);
	arflex_comp_readopt_take(c); /* D61: a state re-adopted, before this cycle's update */
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
int arflex_comp_rt_poll(void *arg, uint64_t now, uint64_t *events)
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

int arflex_comp_rt_cycle(void *arg, uint64_t release_ns)
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
		if (c->fault_crash_after || c->fault_late_every)
			c->fault_updates++; /* one count for every test fault: updates since the START */
		if (c->fault_crash_after && c->fault_updates >= c->fault_crash_after) {
			/* the test fault (D68): no allocation; the default action first, so that
			 * a sanitizer's handler does not turn the crash into an exit */
			struct sigaction dfl = { .sa_handler = SIG_DFL };

			sigaction(SIGSEGV, &dfl, NULL);
			raise(SIGSEGV);
		}
		if (c->fault_late_every && c->fault_updates % c->fault_late_every == 0) {
			/* the test fault (D73): this cycle ends past its next release, so past its
			 * deadline too (one late cycle); spins, as a too slow update would */
			uint64_t until = release_ns + ctl->config.period_ns + 100000u;

			while (arflex_sys_now_ns() < until)
				;
		}
	}
	return r < 0 ? r : 0;
}

int arflex_comp_rt_start(void *arg)
{
	struct arflex_component *c = arg;
	int r;

	c->safe = false;
	c->fault_updates = 0;
	c->clk_binding = 0; /* the first poll takes the clock's binding as new */
	c->clk_seen = 0;
	memset(&c->hbw, 0, sizeof(c->hbw));
	arflex_comp_take_bindings(c);
	check_heartbeat(c, arflex_sys_now_ns());
	r = c->ops->start ? c->ops->start(c, c->ops->user) : 0;
	return r < 0 ? r : arflex_comp_adopt_at_start(c); /* after start: it may reset state */
}

int arflex_comp_rt_stop(void *arg)
{
	struct arflex_component *c = arg;

	if (c->ops->stop)
		c->ops->stop(c, c->ops->user);
	return 0;
}
