/* The C host API reads a component contract (contracts/SPEC.md) with expat. See
 * arflex/host_contract.h for what is read and how it maps, and internal.h for how the reader's
 * files share the work: here the file is read, the document parsed (xml.c), the rules between
 * elements checked and the control block's configuration filled in. */
#include "arflex/host_contract.h"

#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "internal.h"

#define MAX_FILE (1u << 20)     /* SPEC 2.1 */

/* Reads @path (at most MAX_FILE bytes) into a new buffer. Returns 0 or -errno, reported. */
static int read_file(struct loader *L, char **buf, size_t *len)
{
	struct stat st;
	ssize_t n;
	size_t got = 0;
	int fd, r = 0;

	fd = open(L->path, O_RDONLY | O_CLOEXEC);
	if (fd < 0) {
		r = -errno;
		arflex_hc_fail_at(L, 0, 0, "2.1", "file", "cannot open: %s", strerror(-r));
		return r;
	}
	if (fstat(fd, &st) < 0) {
		r = -errno;
		arflex_hc_fail_at(L, 0, 0, "2.1", "file", "cannot stat: %s", strerror(-r));
	} else if (!S_ISREG(st.st_mode)) {
		r = -EINVAL;
		arflex_hc_fail_at(L, 0, 0, "2.1", "file", "not a regular file");
	} else if ((uint64_t)st.st_size > MAX_FILE) {
		r = -EINVAL;
		arflex_hc_fail_at(L, 0, 0, "2.1", "file", "%lld bytes, larger than 1 MiB",
				  (long long)st.st_size);
	} else if (!(*buf = malloc((size_t)st.st_size + 1))) {
		r = -ENOMEM;
		arflex_hc_fail_at(L, 0, 0, "2.1", "file", "out of memory");
	}
	while (!r && got < (size_t)st.st_size) {
		n = read(fd, *buf + got, (size_t)st.st_size - got);
		if (n < 0 && errno == EINTR)
			continue;
		if (n <= 0) {
			r = n < 0 ? -errno : -EIO;
			arflex_hc_fail_at(L, 0, 0, "2.1", "file", "cannot read: %s", strerror(-r));
			free(*buf);
			*buf = NULL;
		} else {
			got += (size_t)n;
		}
	}
	close(fd);
	*len = got;
	return r;
}

/* The rules between elements, once the document is read. */
static void check_whole(struct loader *L)
{
	struct arflex_ctl_config *cfg = &L->c->config;
	unsigned long line = L->root_line, col = L->root_col;
	static const struct { enum kind kind; const char *sec; } req[] = {
		{ K_IMPLEMENTATION, "4" }, { K_RESOURCES, "9" }, { K_CRITICALITY, "10" },
		{ K_FAULT, "11" },
	};

	for (size_t i = 0; i < sizeof(req) / sizeof(req[0]); i++)
		if (!(L->seen & (1u << req[i].kind))) {
			const char *name = arflex_hc_elem_name(req[i].kind);

			arflex_hc_fail_at(L, line, col, req[i].sec, name,
					  "required element <%s> missing", name);
			return;
		}
	if (L->task != ARFLEX_TASK_SERVICE) {
		if (!(L->seen & (1u << K_TIMING))) {
			arflex_hc_fail_at(L, line, col, "8", "timing",
					  "required for a periodic or sporadic task");
			return;
		}
		line = L->timing_line;
		col = L->timing_col;
		if (!L->has_period || !L->has_wcet || !L->has_priority) {
			arflex_hc_fail_at(L, line, col, "8", "timing", "period, wcet and priority "
					  "are required for a periodic or sporadic task");
			return;
		}
	} else if (L->seen & (1u << K_TIMING)) {
		line = L->timing_line;
		col = L->timing_col;
		if (L->has_priority) {
			arflex_hc_fail_at(L, line, col, "8.5", "timing/@priority",
					  "refused on a service");
			return;
		}
		if (L->has_period != L->has_wcet) {
			arflex_hc_fail_at(L, line, col, "8.5", "timing", "period and wcet come "
					  "together on a service, or not at all");
			return;
		}
	}
	if (L->has_period && (L->period == 0 || L->period > 60 * SEC || L->wcet == 0 ||
			      L->wcet > L->deadline || L->deadline > L->period)) {
		arflex_hc_fail_at(L, line, col, "8.2", "timing", "impossible timing: 0 < wcet "
				  "(%" PRIu64 "ns) <= deadline (%" PRIu64 "ns) <= period (%" PRIu64
				  "ns) <= 60s does not hold", L->wcet, L->deadline, L->period);
		return;
	}
	if (L->task != ARFLEX_TASK_SERVICE && L->hb_ms * MS < L->period) {
		arflex_hc_fail_at(L, L->fault_line, L->fault_col, "11", "fault/@heartbeatTimeout",
				  "%" PRIu64 "ms is shorter than the period (%" PRIu64 "ns)",
				  L->hb_ms, L->period);
		return;
	}
	if (L->moves_hw && !L->has_safety_input) {
		arflex_hc_fail_at(L, L->root_line, L->root_col, "4.3",
				  "implementation/@movesHardware",
				  "a component that moves hardware declares a safety input");
		return;
	}
	/* As the DRCR's ControlSetup.config (the CPU is admission's: none here). */
	cfg->period_ns = L->has_period ? L->period : 0;
	cfg->deadline_ns = L->has_period ? L->deadline : 0;
	cfg->hb_timeout_ns = L->hb_ms * MS;
	cfg->cpu_mask = 0;
	if (L->task == ARFLEX_TASK_SERVICE)
		cfg->priority = 0;
	cfg->task_type = (uint32_t)L->task;
	cfg->cfg_flags = (L->moves_hw ? ARFLEX_CFG_MOVES_HARDWARE : 0) |
			 (L->task == ARFLEX_TASK_SERVICE ? ARFLEX_CFG_NO_MLOCK : 0);
	cfg->param_count = L->c->nparams;
	cfg->orphan_hold_ns = L->orphan_ms * MS;
}

int arflex_host_load_contract(struct arflex_host_contract *c, const char *path,
			      const struct arflex_host_type *types, unsigned ntypes, char *err,
			      size_t errlen)
{
	struct loader L;
	char *buf = NULL;
	size_t len = 0;
	int r;

	memset(&L, 0, sizeof(L));
	L.path = path ? path : "(null)";
	L.err = err;
	L.errlen = errlen;
	L.c = c;
	L.types = types;
	L.ntypes = types ? ntypes : 0;
	L.task = -1;
	L.hb_ms = 100;          /* SPEC 11 defaults */
	L.orphan_ms = 2000;
	if (err && errlen)
		err[0] = '\0';
	if (!c || !path) {
		arflex_hc_fail_at(&L, 0, 0, "2", "arguments", "no contract storage or path");
		return -EINVAL;
	}
	memset(c, 0, sizeof(*c));
	r = read_file(&L, &buf, &len);
	if (r)
		goto out;
	r = arflex_hc_read_xml(&L, buf, len);
	if (r)
		goto out;
	if (!L.failed)
		check_whole(&L);
	r = L.failed ? -EINVAL : 0;
out:
	if (L.p)
		XML_ParserFree(L.p);
	free(buf);
	if (r)
		memset(c, 0, sizeof(*c)); /* nothing half declared */
	return r;
}

void arflex_host_contract_opts(struct arflex_host_contract *c, const char *runtime,
			       const char *instance, struct arflex_host_opts *o)
{
	memset(o, 0, sizeof(*o));
	o->runtime = runtime;
	o->instance = instance;
	o->config = c->config;
	o->params = c->nparams ? c->params : NULL;
	o->nparams = c->nparams;
	for (unsigned i = 0; i < c->noutputs; i++)
		c->outputs[i].port = c->output_ports[i];
	o->outputs = c->noutputs ? c->outputs : NULL;
	o->noutputs = c->noutputs;
	o->state = c->has_state ? &c->state : NULL;
}

const struct arflex_host_input *arflex_host_contract_input(const struct arflex_host_contract *c,
							    const char *port)
{
	for (unsigned i = 0; c && port && i < c->ninputs; i++)
		if (!strcmp(c->inputs[i].port, port))
			return &c->inputs[i];
	return NULL;
}
