/* Control block helpers: names, formatting, checks, parameter protocol, stats reader. */
#include "arflex/control.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#define LOAD(p) __atomic_load_n((p), __ATOMIC_ACQUIRE)
#define STORE(p, v) __atomic_store_n((p), (v), __ATOMIC_RELEASE)

bool arflex_ctl_id_valid(const char *id)
{
	size_t n = 0;

	if (!id)
		return false;
	for (; id[n]; n++) {
		char c = id[n];

		if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-'))
			return false;
		if (n >= ARFLEX_ID_MAX)
			return false;
	}
	return n > 0;
}

int arflex_ctl_obj_name(char *buf, size_t size, const char *rid, const char *inst,
			const char *channel)
{
	int n;

	if (!arflex_ctl_id_valid(rid) || !arflex_ctl_id_valid(inst) || !channel || !*channel)
		return -EINVAL;
	n = snprintf(buf, size, "/arflex.%s.%s.%s", rid, inst, channel);
	if (n < 0 || (size_t)n >= size)
		return -ENAMETOOLONG;
	return 0;
}

uint64_t arflex_f64_bits(double v)
{
	uint64_t b;

	memcpy(&b, &v, sizeof(b));
	return b;
}

double arflex_bits_f64(uint64_t bits)
{
	double v;

	memcpy(&v, &bits, sizeof(v));
	return v;
}

static bool param_name_valid(const char *s)
{
	size_t n;

	if (!(s[0] >= 'a' && s[0] <= 'z'))
		return false;
	for (n = 1; s[n]; n++) {
		char c = s[n];

		if (n >= ARFLEX_NAME_SIZE - 1)
			return false;
		if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '.'))
			return false;
	}
	return true;
}

/* Range/type check without the mutability rule. */
static int check_value(const struct arflex_param_slot *s, uint64_t bits)
{
	switch (s->type) {
	case ARFLEX_PARAM_BOOL:
		return bits <= 1 ? 0 : -EINVAL;
	case ARFLEX_PARAM_INT64: {
		int64_t v = (int64_t)bits;

		if (v < (int64_t)s->min_bits || v > (int64_t)s->max_bits)
			return -ERANGE;
		return 0;
	}
	case ARFLEX_PARAM_DOUBLE: {
		double v = arflex_bits_f64(bits);

		if (isnan(v))
			return -EINVAL;
		if (v < arflex_bits_f64(s->min_bits) || v > arflex_bits_f64(s->max_bits))
			return -ERANGE;
		return 0;
	}
	default:
		return -EINVAL;
	}
}

int arflex_ctl_format(struct arflex_ctl *ctl, const struct arflex_ctl_config *config,
		      const struct arflex_param_slot *params, unsigned nparams)
{
	if (nparams > ARFLEX_PARAM_SLOTS)
		return -E2BIG;
	if (!config || config->period_ns == 0 || config->deadline_ns > config->period_ns ||
	    config->priority < 0 || config->priority > 99 || config->safe_mode > 1)
		return -EINVAL;
	memset(ctl, 0, sizeof(*ctl));
	ctl->abi_major = ARFLEX_ABI_MAJOR;
	ctl->abi_minor = ARFLEX_ABI_MINOR;
	ctl->header_size = (uint32_t)offsetof(struct arflex_ctl, stats);
	ctl->size = ARFLEX_CTL_SIZE;
	ctl->config = *config;
	ctl->config.param_count = nparams;
	ctl->stats.latency.min_ns = UINT64_MAX;
	ctl->stats.exec.min_ns = UINT64_MAX;
	for (unsigned i = 0; i < nparams; i++) {
		const struct arflex_param_slot *in = &params[i];
		struct arflex_param_slot *s = &ctl->params[i];

		if (memchr(in->name, 0, sizeof(in->name)) == NULL || !param_name_valid(in->name))
			return -EINVAL;
		for (unsigned j = 0; j < i; j++)
			if (!strcmp(ctl->params[j].name, in->name))
				return -EINVAL;
		if (in->type < ARFLEX_PARAM_BOOL || in->type > ARFLEX_PARAM_DOUBLE)
			return -EINVAL;
		memcpy(s->name, in->name, sizeof(s->name));
		s->type = in->type;
		s->flags = in->flags & ARFLEX_PARAM_MUTABLE;
		s->min_bits = in->min_bits;
		s->max_bits = in->max_bits;
		s->default_bits = in->default_bits;
		if (s->type == ARFLEX_PARAM_BOOL) {
			s->min_bits = 0;
			s->max_bits = 1;
		}
		if (check_value(s, s->default_bits))
			return -EINVAL;
		s->applied_value = s->default_bits;
	}
	/* magic last: a reader seeing it sees a formatted block */
	__atomic_store_n(&ctl->magic, ARFLEX_CTL_MAGIC, __ATOMIC_RELEASE);
	return 0;
}

int arflex_ctl_check(const struct arflex_ctl *ctl, size_t maplen)
{
	if (maplen < 64 || LOAD(&ctl->magic) != ARFLEX_CTL_MAGIC ||
	    ctl->abi_major != ARFLEX_ABI_MAJOR)
		return -EPROTO;
	if ((unsigned)ctl->abi_minor + 1u < ARFLEX_ABI_MINOR + 1u)
		return -EPROTONOSUPPORT;
	if (ctl->size != ARFLEX_CTL_SIZE || maplen < ARFLEX_CTL_SIZE ||
	    ctl->header_size != offsetof(struct arflex_ctl, stats))
		return -EMSGSIZE;
	if (ctl->config.param_count > ARFLEX_PARAM_SLOTS || ctl->config.period_ns == 0)
		return -EPROTO;
	return 0;
}

int arflex_ctl_param_find(const struct arflex_ctl *ctl, const char *name)
{
	for (unsigned i = 0; i < ctl->config.param_count && i < ARFLEX_PARAM_SLOTS; i++)
		if (!strncmp(ctl->params[i].name, name, ARFLEX_NAME_SIZE))
			return (int)i;
	return -ENOENT;
}

int arflex_ctl_param_validate(const struct arflex_ctl *ctl, unsigned idx, uint64_t bits,
			      bool running)
{
	const struct arflex_param_slot *s;

	if (idx >= ctl->config.param_count || idx >= ARFLEX_PARAM_SLOTS)
		return -EINVAL;
	s = &ctl->params[idx];
	if (running && !(s->flags & ARFLEX_PARAM_MUTABLE))
		return -EPERM;
	return check_value(s, bits);
}

uint64_t arflex_ctl_param_request(struct arflex_ctl *ctl, unsigned idx, uint64_t bits)
{
	struct arflex_param_slot *s = &ctl->params[idx];
	uint64_t q = __atomic_load_n(&s->req_seq, __ATOMIC_RELAXED);

	q &= ~(uint64_t)1;
	STORE(&s->req_seq, q + 1);
	__atomic_thread_fence(__ATOMIC_RELEASE);
	__atomic_store_n(&s->req_value, bits, __ATOMIC_RELAXED);
	STORE(&s->req_seq, q + 2);
	return q + 2;
}

int arflex_ctl_param_apply(struct arflex_ctl *ctl, unsigned idx, bool running)
{
	struct arflex_param_slot *s = &ctl->params[idx];
	uint64_t r1, r2, v;
	int st;

	r1 = LOAD(&s->req_seq);
	if ((r1 & 1) || r1 == __atomic_load_n(&s->applied_seq, __ATOMIC_RELAXED))
		return 0;
	v = __atomic_load_n(&s->req_value, __ATOMIC_RELAXED);
	__atomic_thread_fence(__ATOMIC_ACQUIRE);
	r2 = __atomic_load_n(&s->req_seq, __ATOMIC_RELAXED);
	if (r1 != r2)
		return 0;
	st = arflex_ctl_param_validate(ctl, idx, v, running);
	if (!st)
		__atomic_store_n(&s->applied_value, v, __ATOMIC_RELAXED);
	__atomic_store_n(&s->applied_status, st, __ATOMIC_RELAXED);
	STORE(&s->applied_seq, r1);
	return 1;
}

int arflex_ctl_param_apply_all(struct arflex_ctl *ctl, bool running)
{
	int n = 0;

	for (unsigned i = 0; i < ctl->config.param_count && i < ARFLEX_PARAM_SLOTS; i++)
		n += arflex_ctl_param_apply(ctl, i, running);
	return n;
}

uint64_t arflex_ctl_param_value(const struct arflex_ctl *ctl, unsigned idx)
{
	return LOAD(&ctl->params[idx].applied_value);
}

int arflex_ctl_stats_read(const struct arflex_ctl *ctl, struct arflex_stats *out)
{
	for (int i = 0; i < 1000; i++) {
		uint64_t s1 = LOAD(&ctl->stats.seq), s2;

		if (s1 & 1)
			continue;
		/* The writer uses relaxed atomics on each word; copying word by word with
		 * relaxed loads keeps the sanitizers and the memory model happy. */
		const uint64_t *src = (const uint64_t *)&ctl->stats;
		uint64_t *dst = (uint64_t *)out;

		for (size_t k = 0; k < sizeof(*out) / 8; k++)
			dst[k] = __atomic_load_n(&src[k], __ATOMIC_RELAXED);
		__atomic_thread_fence(__ATOMIC_ACQUIRE);
		s2 = __atomic_load_n(&ctl->stats.seq, __ATOMIC_RELAXED);
		if (s1 == s2)
			return 0;
	}
	return -EAGAIN;
}

uint64_t arflex_metric_percentile(const struct arflex_metric *m, double p)
{
	uint64_t total = 0, target, acc = 0;

	for (unsigned i = 0; i <= ARFLEX_HIST_BINS; i++)
		total += m->hist[i];
	if (!total)
		return 0;
	target = (uint64_t)ceil((double)total * p / 100.0);
	if (target == 0)
		target = 1;
	for (unsigned i = 0; i < ARFLEX_HIST_BINS; i++) {
		acc += m->hist[i];
		if (acc >= target) {
			uint64_t edge = (uint64_t)(i + 1) * ARFLEX_HIST_BIN_NS;

			return edge < m->max_ns ? edge : m->max_ns;
		}
	}
	return m->max_ns;
}

uint32_t arflex_ctl_state(const struct arflex_ctl *ctl)
{
	return LOAD(&ctl->state);
}

uint32_t arflex_ctl_flags(const struct arflex_ctl *ctl)
{
	return LOAD(&ctl->flags);
}

uint32_t arflex_ctl_hold(const struct arflex_ctl *ctl)
{
	return __atomic_load_n(&ctl->hold, __ATOMIC_ACQUIRE);
}

void arflex_ctl_set_runtime_hb(struct arflex_ctl *ctl, uint64_t now_ns)
{
	STORE(&ctl->runtime_hb_ns, now_ns);
}

bool arflex_hb_judge(struct arflex_hb_window *w, uint64_t hb, uint64_t now, uint64_t period_ns,
		     uint64_t timeout_ns)
{
	uint64_t step;

	if (!w->last_now) {
		w->silence_ns = now > hb ? now - hb : 0;
	} else if (hb != w->last_hb) {
		w->silence_ns = 0;
	} else {
		/* a late cycle of our own is the machine, not the runtime: bounded step */
		step = now > w->last_now ? now - w->last_now : 0;
		if (step > 2 * period_ns)
			step = 2 * period_ns;
		w->silence_ns += step;
	}
	w->last_hb = hb;
	w->last_now = now ? now : 1;
	return timeout_ns && w->silence_ns > timeout_ns;
}
