/* The re-adopt of a running half (arflex/component.h, docs/DECISIONS.md D61): the manager's
 * READOPT names the state segment of the half this one replaces; the RT thread takes its newest
 * value at its next cycle boundary, before that cycle's update, and the reply says how that went.
 * The switch of an update whose new half ran in shadow (D42) since its START: the new half takes
 * the old half's state again at the switch instead of going on from what it evolved to. */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"

int arflex_component_readopt(struct arflex_component *c, arflex_readopt_fn fn)
{
	if (!c->configuring)
		return -EINVAL;
	c->readopt.fn = fn;
	return 0;
}

/* D70: after configure, before READY (main thread): the control block says whether this half
 * can re-adopt once running, so that the manager knows it before a shadow run's START rather
 * than at the switch. Cleared at attach with the other RT bits (a restart configures afresh). */
void arflex_comp_readopt_advertise(struct arflex_component *c)
{
	if (c->readopt.fn)
		__atomic_or_fetch(&c->ctl->flags, ARFLEX_FLAG_READOPT, __ATOMIC_RELEASE);
}

static void release(struct arflex_component *c)
{
	if (c->readopt.src) {
		arflex_port_close(c->readopt.src);
		free(c->readopt.src);
		c->readopt.src = NULL;
	}
	free(c->readopt.buf);
	c->readopt.buf = NULL;
}

/* RT thread, at a cycle boundary: no blocking, no allocation, no printing. */
void arflex_comp_readopt_take(struct arflex_component *c)
{
	struct arflex_readopt *ra = &c->readopt;
	struct arflex_adopted_state s;
	struct arflex_port *p;
	uint32_t posted = READOPT_POSTED;
	uint64_t age = 0;
	int r;

	if (LOAD(&ra->phase) != READOPT_POSTED)
		return;
	if (!__atomic_compare_exchange_n(&ra->phase, &posted, READOPT_TAKING, false,
					 __ATOMIC_ACQ_REL, __ATOMIC_ACQUIRE))
		return; /* withdrawn by the mailbox thread at its deadline */
	p = ra->src;
	p->last_seq = 0; /* the newest value, whether or not read before */
	r = arflex_state_read(p, ra->buf, p->elem_size, &ra->seq);
	if (r == 0) {
		r = -ENODATA; /* the old half published nothing: nothing to continue from */
	} else if (r > 0) {
		(void)arflex_port_age(p, arflex_sys_now_ns(), &age);
		memset(&s, 0, sizeof(s));
		s.type_name = p->hdr->type_name;
		s.major = p->hdr->type_major;
		s.minor = p->hdr->type_minor;
		s.data = ra->buf;
		s.length = p->elem_size;
		s.age_ns = age;
		ra->age_ns = age;
		r = ra->fn(c, c->ops->user, &s);
		if (r > 0)
			r = 0;
	}
	ra->result = r;
	STORE(&ra->phase, READOPT_DONE);
}

/* The test fault of READOPT (as D58's ARFLEX_FAULT_START_ERRNO): ARFLEX_FAULT_READOPT_ERRNO=<n>,
 * 1..4095, makes this half refuse every READOPT with -n, as a hook that cannot take the state
 * would. Only the update tests' deliberately faulty versions set it (a script that execs the
 * real executable); nothing shipped does. 0: not set (mailbox thread). */
static int fault_readopt_env(void)
{
	const char *s = arflex_sys_fault_env("ARFLEX_FAULT_READOPT_ERRNO");
	char *end;
	long n;

	if (!s || !*s)
		return 0;
	n = strtol(s, &end, 10);
	return *end || n < 1 || n > 4095 ? 0 : (int)n;
}

/* Mailbox thread, while running. */
int arflex_comp_readopt_cmd(struct arflex_component *c, const struct arflex_msg *m)
{
	const struct arflex_msg_bind *b = &m->u.bind;
	struct arflex_readopt *ra = &c->readopt;
	struct arflex_port *p;
	uint32_t posted = READOPT_POSTED;
	uint64_t deadline;
	int r;

	if (!ra->fn)
		return -EOPNOTSUPP; /* this executable cannot take a state over while it runs */
	r = fault_readopt_env();
	if (r) {
		arflex_comp_log(c, "READOPT refused: test fault ARFLEX_FAULT_READOPT_ERRNO=%d (%s)", r,
				strerror(r));
		return -r;
	}
	if (memchr(b->shm_name, 0, sizeof(b->shm_name)) == NULL || !b->shm_name[0])
		return -EINVAL;
	p = calloc(1, sizeof(*p));
	if (!p)
		return -ENOMEM;
	/* no type check here, as ADOPT: another type or version is the hook's to convert */
	r = arflex_port_open(p, b->shm_name, false, false, ARFLEX_PORT_STATE, NULL);
	if (r) {
		arflex_comp_log(c, "READOPT %s: %s", b->shm_name, strerror(-r));
		free(p);
		return r;
	}
	ra->buf = calloc(1, p->elem_size ? p->elem_size : 1);
	if (!ra->buf) {
		arflex_port_close(p);
		free(p);
		return -ENOMEM;
	}
	ra->src = p;
	ra->result = 0;
	STORE(&ra->phase, READOPT_POSTED);
	deadline = arflex_comp_apply_deadline(c);
	while (LOAD(&ra->phase) != READOPT_DONE) {
		if (arflex_sys_now_ns() > deadline &&
		    __atomic_compare_exchange_n(&ra->phase, &posted, READOPT_IDLE, false,
						__ATOMIC_ACQ_REL, __ATOMIC_ACQUIRE)) {
			arflex_comp_log(c, "READOPT %s: not taken by the RT thread in time", p->name);
			release(c);
			return -ETIMEDOUT;
		}
		posted = READOPT_POSTED; /* the RT thread is taking it: its hook is short */
		arflex_comp_wait_short();
	}
	r = ra->result;
	if (r == 0)
		arflex_comp_log(c, "re-adopted the state block %s %u.%u of %s while running (value %llu, "
				"%llu us old)", p->hdr->type_name, p->hdr->type_major,
				p->hdr->type_minor, p->name, (unsigned long long)ra->seq,
				(unsigned long long)(ra->age_ns / 1000));
	else if (r == -ENODATA)
		arflex_comp_log(c, "READOPT %s: nothing published: not re-adopted", p->name);
	else
		arflex_comp_log(c, "READOPT %s: the re-adopt hook refused %s %u.%u: %s", p->name,
				p->hdr->type_name, p->hdr->type_major, p->hdr->type_minor,
				strerror(-r));
	release(c);
	STORE(&ra->phase, READOPT_IDLE);
	return r;
}
