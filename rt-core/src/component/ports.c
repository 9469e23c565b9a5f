/* The ports of an RT half (arflex/component.h): outputs and inputs declared in the configure
 * hook, and the manager's BIND/UNBIND of an input, handed from the mailbox thread to the RT
 * thread at its next cycle boundary (pending -> cur -> retired, then unmapped by the mailbox
 * thread). */
#include "arflex/component.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"

static struct arflex_port unbind_marker; /* pending: unbind */

/* ---- declaration (configure) --------------------------------------------------------- */

/* /arflex.<rid>.<inst>.out.<port> (ABI.md 2). */
int arflex_comp_output_obj_name(const struct arflex_component *c, const char *port, char *name,
				size_t size)
{
	char chan[ARFLEX_NAME_SIZE + 8];

	snprintf(chan, sizeof(chan), "out.%s", port);
	return arflex_ctl_obj_name(name, size, c->rid, c->inst, chan);
}

int arflex_component_output(struct arflex_component *c, const char *port,
			    enum arflex_port_method method, const struct arflex_port_type *type,
			    struct arflex_port **out)
{
	char name[ARFLEX_OBJ_NAME_SIZE];
	int r;

	if (!c->configuring || !arflex_port_name_valid(port) || !type || !type->name)
		return -EINVAL;
	for (unsigned i = 0; i < c->noutputs; i++)
		if (!strcmp(c->output_names[i], port))
			return -EEXIST;
	if (c->noutputs >= ARFLEX_MAX_OUTPUTS)
		return -ENOSPC;
	r = arflex_comp_output_obj_name(c, port, name, sizeof(name));
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

/* Unmaps and frees a binding (a provider's segment mapped at BIND); not the unbind marker. */
static void close_binding(struct arflex_port *p)
{
	if (p && p != &unbind_marker) {
		arflex_port_close(p);
		free(p);
	}
}

/* At exit: every binding and every output. */
void arflex_comp_close_ports(struct arflex_component *c)
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

/* ---- binding (mailbox thread -> RT thread) ------------------------------------------- */

/* RT thread, at a cycle boundary (and the mailbox thread once the RT thread stopped): takes
 * the bindings posted since the last boundary. */
void arflex_comp_take_bindings(struct arflex_component *c)
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

/* Mailbox thread, the RT thread stopped: takes what is still posted and unmaps what was
 * replaced. */
void arflex_comp_retire_bindings(struct arflex_component *c)
{
	arflex_comp_take_bindings(c); /* a binding posted at the very end */
	for (unsigned i = 0; i < c->ninputs; i++)
		close_binding(XCHG(&c->inputs[i].retired, NULL));
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
	deadline = arflex_comp_apply_deadline(c);
	while (LOAD(&in->done_seq) != seq) {
		if (arflex_sys_now_ns() > deadline) {
			struct arflex_port *back = XCHG(&in->pending, NULL);

			if (back == p) {
				close_binding(p);
				return -ETIMEDOUT;
			}
			deadline = UINT64_MAX; /* taken right now: done_seq follows */
		}
		arflex_comp_wait_short();
	}
	close_binding(XCHG(&in->retired, NULL));
	return 0;
}

int arflex_comp_bind_cmd(struct arflex_component *c, struct arflex_msg *m)
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
