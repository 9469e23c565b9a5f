/* Probe component for the tests: logs its hooks, exposes what it sees on an output port. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "arflex/component.h"

struct probe_out {
	uint64_t updates;
	uint64_t safe_calls;
	uint64_t safe_firsts;
	int64_t gain;
	uint64_t torn;          /* a parameter changed in the middle of an update */
	uint64_t in_value;      /* last value read on input 'in' */
	uint64_t in_reads;
	uint64_t in_bound;
	uint64_t in_binding;    /* arflex_input_binding */
	uint64_t adopt_calls;   /* D41 */
	uint64_t adopted;
	uint64_t state_value;
	uint64_t prepare_calls; /* D57: the ADOPT's prepare hook */
	uint64_t prepared;      /* the value it saw */
};

static const struct arflex_port_type out_type = { "test.ProbeOut", 1, 0,
						  sizeof(struct probe_out) };
static const struct arflex_port_type in_type = { "test.Value", 1, 0, sizeof(uint64_t) };
static const struct arflex_port_type state_type = { "test.ProbeState", 1, 0, sizeof(uint64_t) };

static struct probe {
	FILE *log;
	struct arflex_port *out;
	struct arflex_input *in;
	int gain;
	struct probe_out o;
	bool logged_update;
	uint64_t require_reset_at; /* ARFLEX_PROBE_REQUIRE_RESET_AT: latch a reset at that update */
} pr;

static void note(const char *what)
{
	if (pr.log) {
		fprintf(pr.log, "%s\n", what);
		fflush(pr.log);
	}
}

/* D57: ARFLEX_PROBE_PREPARE=refuse refuses the ADOPT (-EBADMSG); any other value counts the
 * calls and keeps the value seen (mailbox thread; the probe is not running then). */
static int prepare(struct arflex_component *c, void *user, const struct arflex_adopted_state *s)
{
	uint64_t v = 0;

	(void)c;
	(void)user;
	if (!strcmp(getenv("ARFLEX_PROBE_PREPARE"), "refuse"))
		return -EBADMSG;
	if (s->length >= sizeof(v))
		memcpy(&v, s->data, sizeof(v));
	pr.o.prepared = v;
	pr.o.prepare_calls++;
	return 0;
}

static int adopt(struct arflex_component *c, void *user, const struct arflex_adopted_state *s);

/* D61: ARFLEX_PROBE_READOPT=refuse refuses every re-adopt (-EBADMSG), state untouched. */
static int readopt_refuse(struct arflex_component *c, void *user,
			  const struct arflex_adopted_state *s)
{
	(void)c;
	(void)user;
	(void)s;
	return -EBADMSG;
}

static int configure(struct arflex_component *c, void *user)
{
	const char *path = getenv("ARFLEX_PROBE_LOG");
	int r;

	(void)user;
	if (path) {
		pr.log = fopen(path, "a");
		if (!pr.log)
			return -errno;
	}
	note("configure");
	r = arflex_component_output(c, "out", ARFLEX_PORT_STATE, &out_type, &pr.out);
	if (r)
		goto out_fail;
	r = arflex_component_input(c, "in", ARFLEX_PORT_STATE, &in_type, &pr.in);
	if (r)
		goto out_fail;
	r = arflex_component_state(c, &state_type, NULL); /* D41: -ENOENT without a segment */
	if (r && r != -ENOENT)
		goto out_fail;
	pr.gain = arflex_component_param(c, "gain");
	if (pr.gain < 0) {
		r = pr.gain;
		goto out_fail;
	}
	if (getenv("ARFLEX_PROBE_PREPARE")) {
		r = arflex_component_adopt_prepare(c, prepare);
		if (r)
			goto out_fail;
	}
	if (getenv("ARFLEX_PROBE_READOPT")) { /* D61: the adopt hook re-adopts too, or refuses */
		const char *how = getenv("ARFLEX_PROBE_READOPT");
		arflex_readopt_fn fn = adopt;

		if (!strcmp(how, "refuse"))
			fn = readopt_refuse;
		else if (!strcmp(how, "null"))
			fn = NULL; /* D70: registered, but no hook */
		r = arflex_component_readopt(c, fn);
		if (r)
			goto out_fail;
	}
	if (getenv("ARFLEX_PROBE_REQUIRE_RESET_AT"))
		pr.require_reset_at = strtoull(getenv("ARFLEX_PROBE_REQUIRE_RESET_AT"), NULL, 10);
	if (getenv("ARFLEX_PROBE_FAIL_CONFIGURE")) {
		r = -ENOTSUP;
		goto out_fail;
	}
	return 0;

out_fail:
	note("configure-failed");
	if (pr.log)
		fclose(pr.log);
	pr.log = NULL;
	return r;
}

static int start(struct arflex_component *c, void *user)
{
	(void)c;
	(void)user;
	note("start");
	pr.logged_update = false;
	return getenv("ARFLEX_PROBE_FAIL_START") ? -ENOTSUP : 0;
}

static int update(struct arflex_component *c, void *user, uint64_t release_ns)
{
	int64_t g1 = arflex_param_i64(c, pr.gain), g2;
	uint64_t v;
	volatile uint64_t spin = 0;

	(void)user;
	(void)release_ns;
	for (int i = 0; i < 2000; i++)
		spin += (uint64_t)i;
	pr.o.updates++;
	if (arflex_input_state_read(pr.in, &v, sizeof(v), NULL) == 1) {
		pr.o.in_value = v;
		pr.o.in_reads++;
	}
	pr.o.in_bound = arflex_input_bound(pr.in);
	pr.o.in_binding = arflex_input_binding(pr.in);
	g2 = arflex_param_i64(c, pr.gain);
	if (g1 != g2)
		pr.o.torn++;
	pr.o.gain = g2;
	if (pr.require_reset_at && pr.o.updates == pr.require_reset_at)
		arflex_component_require_reset(c);
	pr.logged_update = true;
	pr.o.state_value = pr.o.adopted + pr.o.updates;
	arflex_component_state_publish(c, &pr.o.state_value, sizeof(pr.o.state_value), release_ns);
	return arflex_state_write(pr.out, &pr.o, sizeof(pr.o));
}

/* D41: test.ProbeState 1.x as it is, test.OldProbeState 0.x converted (x 10), else refused. */
static int adopt(struct arflex_component *c, void *user, const struct arflex_adopted_state *s)
{
	uint64_t v;

	(void)c;
	(void)user;
	if (s->length < sizeof(v))
		return -EMSGSIZE;
	memcpy(&v, s->data, sizeof(v));
	if (!strcmp(s->type_name, "test.ProbeState") && s->major == 1)
		pr.o.adopted = v;
	else if (!strcmp(s->type_name, "test.OldProbeState") && s->major == 0)
		pr.o.adopted = v * 10;
	else
		return -EPROTOTYPE;
	pr.o.adopt_calls++;
	return 0;
}

static int safe(struct arflex_component *c, void *user, enum arflex_safe_mode mode, bool first)
{
	(void)c;
	(void)user;
	(void)mode;
	pr.o.safe_calls++;
	pr.o.safe_firsts += first;
	return arflex_state_write(pr.out, &pr.o, sizeof(pr.o));
}

static void stop(struct arflex_component *c, void *user)
{
	(void)c;
	(void)user;
	if (pr.logged_update)
		note("update");
	note("stop");
}

static void cleanup(struct arflex_component *c, void *user)
{
	(void)c;
	(void)user;
	note("cleanup");
	if (pr.log)
		fclose(pr.log);
}

static const struct arflex_component_ops ops = {
	.name = "probe",
	.configure = configure,
	.start = start,
	.update = update,
	.stop = stop,
	.cleanup = cleanup,
	.safe = safe,
	.adopt = adopt,
};

int main(int argc, char **argv)
{
	return arflex_component_main(argc, argv, &ops);
}
