/* The state block of an RT half and its adoption by the next version (arflex/component.h,
 * docs/DECISIONS.md D41). */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"

#define NOT_TRIED 2 /* state.result before the START that adopts */

int arflex_component_state(struct arflex_component *c, const struct arflex_port_type *type,
			   struct arflex_port **out)
{
	char name[ARFLEX_OBJ_NAME_SIZE];
	int r;

	if (out)
		*out = NULL;
	if (!c->configuring || !type || !type->name || strlen(type->name) >= ARFLEX_TYPE_NAME_SIZE)
		return -EINVAL;
	if (c->state.open)
		return -EEXIST;
	r = arflex_ctl_obj_name(name, sizeof(name), c->rid, c->inst, "state");
	if (r)
		return r;
	r = arflex_port_open(&c->state.own, name, true, true, ARFLEX_PORT_STATE, type);
	if (r) {
		if (r != -ENOENT) /* -ENOENT: the manager keeps no state for this half */
			arflex_comp_log(c, "state block (%s): %s", name, strerror(-r));
		return r;
	}
	snprintf(c->state.type_name, sizeof(c->state.type_name), "%s", type->name);
	c->state.type = *type;
	c->state.type.name = c->state.type_name;
	c->state.open = true;
	if (out)
		*out = &c->state.own;
	return 0;
}

int arflex_component_state_publish(struct arflex_component *c, const void *val, size_t len,
				   uint64_t stamp_ns)
{
	if (!c->state.open)
		return 0;
	return arflex_state_write_at(&c->state.own, val, len, stamp_ns);
}

int arflex_component_adopt_prepare(struct arflex_component *c, arflex_adopt_prepare_fn fn)
{
	if (!c->configuring)
		return -EINVAL;
	c->state.prepare = fn;
	return 0;
}

bool arflex_component_state_open(const struct arflex_component *c)
{
	return c->state.open;
}

static void release_src(struct arflex_component *c)
{
	if (c->state.src) {
		arflex_port_close(c->state.src);
		free(c->state.src);
		c->state.src = NULL;
	}
	free(c->state.buf);
	c->state.buf = NULL;
}

int arflex_comp_adopt_cmd(struct arflex_component *c, const struct arflex_msg *m)
{
	const struct arflex_msg_bind *b = &m->u.bind;
	struct arflex_port *p;
	void *buf;
	int r;

	if (!c->ops->adopt)
		return -EOPNOTSUPP; /* this executable cannot take a state over */
	if (memchr(b->shm_name, 0, sizeof(b->shm_name)) == NULL)
		return -EINVAL;
	release_src(c); /* a second ADOPT replaces the first */
	if (!b->shm_name[0])
		return 0; /* "" withdraws it */
	p = calloc(1, sizeof(*p));
	if (!p)
		return -ENOMEM;
	/* No type check here: a state of another type or version is the adopt hook's to convert
	 * (the DRCR's plan admitted only what the new contract declares it adopts). */
	r = arflex_port_open(p, b->shm_name, false, false, ARFLEX_PORT_STATE, NULL);
	if (r) {
		arflex_comp_log(c, "ADOPT %s: %s", b->shm_name, strerror(-r));
		free(p);
		return r;
	}
	buf = calloc(1, p->elem_size ? p->elem_size : 1);
	if (!buf) {
		arflex_port_close(p);
		free(p);
		return -ENOMEM;
	}
	c->state.src = p;
	c->state.buf = buf;
	c->state.result = NOT_TRIED;
	if (c->state.prepare) {
		/* D57: the hook reads what does not fit a state block, here off the RT thread */
		struct arflex_adopted_state s;
		uint64_t age = 0;
		uint64_t seen = p->last_seq;

		r = arflex_state_read(p, buf, p->elem_size, NULL);
		p->last_seq = seen; /* START reads the newest value again, as new */
		if (r > 0) {
			(void)arflex_port_age(p, arflex_sys_now_ns(), &age);
			memset(&s, 0, sizeof(s));
			s.type_name = p->hdr->type_name;
			s.major = p->hdr->type_major;
			s.minor = p->hdr->type_minor;
			s.data = buf;
			s.length = p->elem_size;
			s.age_ns = age;
			r = c->state.prepare(c, c->ops->user, &s);
			if (r < 0) {
				arflex_comp_log(c, "ADOPT %s: refused: %s", b->shm_name, strerror(-r));
				release_src(c);
				return r;
			}
		}
	}
	return 0;
}

int arflex_comp_adopt_at_start(struct arflex_component *c)
{
	struct arflex_port *p = c->state.src;
	struct arflex_adopted_state s;
	uint64_t now, age = 0;
	int r;

	if (!p)
		return 0;
	r = arflex_state_read(p, c->state.buf, p->elem_size, &c->state.seq);
	if (r <= 0) {
		c->state.result = r; /* nothing published yet (0) or a damaged segment */
		return 0;            /* the half starts as without a state */
	}
	now = arflex_sys_now_ns();
	(void)arflex_port_age(p, now, &age);
	memset(&s, 0, sizeof(s));
	s.type_name = p->hdr->type_name;
	s.major = p->hdr->type_major;
	s.minor = p->hdr->type_minor;
	s.data = c->state.buf;
	s.length = p->elem_size;
	s.age_ns = age;
	c->state.age_ns = age;
	r = c->ops->adopt(c, c->ops->user, &s);
	c->state.result = r < 0 ? r : 1;
	return r < 0 ? r : 0; /* a refusal refuses the START */
}

void arflex_comp_adopt_done(struct arflex_component *c)
{
	struct arflex_port *p = c->state.src;

	if (!p)
		return;
	if (c->state.result == 1)
		arflex_comp_log(c, "adopted the state block %s %u.%u of %s (value %llu, %llu us old)",
				p->hdr->type_name, p->hdr->type_major, p->hdr->type_minor, p->name,
				(unsigned long long)c->state.seq,
				(unsigned long long)(c->state.age_ns / 1000));
	else if (c->state.result == NOT_TRIED)
		arflex_comp_log(c, "ADOPT %s: the START failed before the adoption", p->name);
	else if (c->state.result == 0)
		arflex_comp_log(c, "ADOPT %s: nothing published yet: started without a state",
				p->name);
	else
		arflex_comp_log(c, "ADOPT %s: the adopt hook refused %s %u.%u: %s", p->name,
				p->hdr->type_name, p->hdr->type_major, p->hdr->type_minor,
				strerror(-c->state.result));
	release_src(c); /* once: a later START starts as without a state */
}

void arflex_comp_state_close(struct arflex_component *c)
{
	release_src(c);
	if (c->state.open) {
		arflex_port_close(&c->state.own);
		c->state.open = false;
	}
}
