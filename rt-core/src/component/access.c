/* The component template's accessors: parameters, the control block, holds, and the inputs a
 * component reads (with the per-input count of rejected values, ABI 1.2). */
#include "arflex/component.h"

#include <errno.h>

#include "internal.h"

/* ---- accessors ------------------------------------------------------------------------ */

int arflex_component_param(const struct arflex_component *c, const char *name)
{
	return arflex_ctl_param_find(c->ctl, name);
}

int64_t arflex_param_i64(const struct arflex_component *c, int idx)
{
	return (int64_t)arflex_ctl_param_value(c->ctl, (unsigned)idx);
}

double arflex_param_f64(const struct arflex_component *c, int idx)
{
	return arflex_bits_f64(arflex_ctl_param_value(c->ctl, (unsigned)idx));
}

uint64_t arflex_param_writes(const struct arflex_component *c, int idx)
{
	return LOAD(&c->ctl->params[idx].applied_seq);
}

bool arflex_param_bool(const struct arflex_component *c, int idx)
{
	return arflex_ctl_param_value(c->ctl, (unsigned)idx) != 0;
}

const struct arflex_ctl *arflex_component_ctl(const struct arflex_component *c)
{
	return c->ctl;
}

const char *arflex_component_runtime(const struct arflex_component *c)
{
	return c->rid;
}

const char *arflex_component_instance(const struct arflex_component *c)
{
	return c->inst;
}

bool arflex_component_safe_active(const struct arflex_component *c)
{
	return (arflex_ctl_flags(c->ctl) & ARFLEX_FLAG_SAFE_ACTIVE) != 0;
}

void arflex_component_require_reset(struct arflex_component *c)
{
	__atomic_or_fetch(&c->ctl->flags, ARFLEX_FLAG_RESET_REQUIRED, __ATOMIC_RELEASE);
}

void arflex_component_hold(struct arflex_component *c, uint32_t cause, uint32_t detail,
			   uint32_t input)
{
	uint32_t w = cause == ARFLEX_HOLD_NONE ? 0 : ARFLEX_HOLD_WORD(cause, detail, input);

	if (__atomic_load_n(&c->ctl->hold, __ATOMIC_RELAXED) != w)
		STORE(&c->ctl->hold, w);
}

uint32_t arflex_input_index(const struct arflex_component *c, const struct arflex_input *in)
{
	return (uint32_t)(in - c->inputs);
}

bool arflex_input_bound(const struct arflex_input *in)
{
	return in->cur != NULL;
}

uint32_t arflex_input_binding(const struct arflex_input *in)
{
	return in->cur ? in->binding : 0;
}

struct arflex_port *arflex_input_port(struct arflex_input *in)
{
	return in->cur;
}

int arflex_input_age(const struct arflex_input *in, uint64_t now_ns, uint64_t *age_ns)
{
	return in->cur ? arflex_port_age(in->cur, now_ns, age_ns) : -ENOTCONN;
}

_Static_assert(ARFLEX_MAX_INPUTS <= ARFLEX_CTL_INPUTS, "every input has a count slot");

void arflex_input_reject(struct arflex_input *in)
{
	if (in->warnings)
		__atomic_add_fetch(&in->warnings[ARFLEX_WARN_INPUT], 1, __ATOMIC_RELAXED);
	if (in->count)
		__atomic_add_fetch(&in->count->rejects, 1, __ATOMIC_RELAXED);
}

/* A damaged input header (-EPROTO) is a rejected value of that input, whatever the method. */
static int counted(struct arflex_input *in, int r)
{
	if (r == -EPROTO)
		arflex_input_reject(in);
	return r;
}

int arflex_input_state_read(struct arflex_input *in, void *out, size_t len, uint64_t *seq)
{
	return in->cur ? counted(in, arflex_state_read(in->cur, out, len, seq)) : -ENOTCONN;
}

int arflex_input_stream_pop(struct arflex_input *in, void *out, size_t len)
{
	return in->cur ? counted(in, arflex_stream_pop(in->cur, out, len)) : -ENOTCONN;
}

int arflex_input_frame_acquire(struct arflex_input *in, struct arflex_frame_view *v)
{
	return in->cur ? counted(in, arflex_frame_acquire(in->cur, v)) : -ENOTCONN;
}
