/* Manager side in C: create/destroy an instance's objects, spawn, command. */
#include "arflex/host.h"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#define LOAD(p) __atomic_load_n((p), __ATOMIC_ACQUIRE)

static int create_ctl(struct arflex_host *h, const struct arflex_host_opts *o)
{
	void *base;
	int fd, r;

	fd = arflex_sys_shm_open(h->ctl_name, O_CREAT | O_EXCL | O_RDWR, 0600);
	if (fd < 0)
		return fd;
	r = arflex_sys_ftruncate(fd, ARFLEX_CTL_SIZE);
	if (r)
		goto out_unlink;
	r = arflex_sys_mmap(&base, ARFLEX_CTL_SIZE, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
	if (r)
		goto out_unlink;
	r = arflex_ctl_format(base, &o->config, o->params, o->nparams);
	if (r) {
		fprintf(stderr, "arflex host: %s: invalid configuration or parameter table "
			"(period > 0, deadline <= period, priority 0..99, parameter names "
			"[a-z][a-z0-9_.]{0,30}, unique, defaults in range)\n", h->ctl_name);
		goto out_unmap;
	}
	arflex_ctl_set_runtime_hb(base, arflex_sys_now_ns());
	arflex_sys_close(fd);
	h->ctl = base;
	return 0;

out_unmap:
	arflex_sys_munmap(base, ARFLEX_CTL_SIZE);
out_unlink:
	arflex_sys_close(fd);
	arflex_sys_shm_unlink(h->ctl_name);
	return r;
}

int arflex_host_create(struct arflex_host *h, const struct arflex_host_opts *o)
{
	int r;

	memset(h, 0, sizeof(*h));
	h->mb.tx = h->mb.rx = (mqd_t)-1;
	if (!o || !arflex_ctl_id_valid(o->runtime) || !arflex_ctl_id_valid(o->instance)) {
		fprintf(stderr, "arflex host: runtime id '%s' or instance '%s' is not "
			"[a-z0-9-]{1,40}\n", o && o->runtime ? o->runtime : "(null)",
			o && o->instance ? o->instance : "(null)");
		return -EINVAL;
	}
	if (o->noutputs > ARFLEX_MAX_OUTPUTS || (o->noutputs && !o->outputs) ||
	    (o->nparams && !o->params)) {
		fprintf(stderr, "arflex host: %s: bad output or parameter list\n", o->instance);
		return -EINVAL;
	}
	for (unsigned i = 0; i < o->noutputs; i++) {
		if (!arflex_port_name_valid(o->outputs[i].port) ||
		    !arflex_port_segment_size(&o->outputs[i].spec)) {
			fprintf(stderr, "arflex host: %s: output port %u ('%s') has a bad name "
				"([a-z0-9_]{1,31}) or spec\n", o->instance, i,
				o->outputs[i].port ? o->outputs[i].port : "(null)");
			return -EINVAL;
		}
		for (unsigned j = 0; j < i; j++)
			if (!strcmp(o->outputs[j].port, o->outputs[i].port)) {
				fprintf(stderr, "arflex host: %s: output port '%s' declared twice\n",
					o->instance, o->outputs[i].port);
				return -EINVAL;
			}
	}
	strcpy(h->runtime, o->runtime);
	strcpy(h->instance, o->instance);
	r = arflex_ctl_obj_name(h->ctl_name, sizeof(h->ctl_name), h->runtime, h->instance, "ctl");
	if (r)
		return r;
	r = create_ctl(h, o);
	if (r)
		return r;
	r = arflex_mailbox_create(&h->mb, h->runtime, h->instance);
	if (r)
		goto out_ctl;
	for (unsigned i = 0; i < o->noutputs; i++) {
		char chan[ARFLEX_NAME_SIZE + 8], name[ARFLEX_OBJ_NAME_SIZE];

		snprintf(chan, sizeof(chan), "out.%s", o->outputs[i].port);
		r = arflex_ctl_obj_name(name, sizeof(name), h->runtime, h->instance, chan);
		if (r)
			goto out_ports;
		r = arflex_port_create(&h->outputs[i], name, &o->outputs[i].spec);
		if (r)
			goto out_ports;
		snprintf(h->output_ports[i], ARFLEX_NAME_SIZE, "%s", o->outputs[i].port);
		h->noutputs = i + 1;
	}
	if (o->state) {
		char name[ARFLEX_OBJ_NAME_SIZE];
		struct arflex_port_spec spec = { .method = ARFLEX_PORT_STATE, .type = *o->state,
						 .depth = 1 };

		r = arflex_ctl_obj_name(name, sizeof(name), h->runtime, h->instance, "state");
		if (r)
			goto out_ports;
		r = arflex_port_create(&h->state, name, &spec);
		if (r)
			goto out_ports;
		h->has_state = true;
	}
	return 0;

out_ports:
	for (unsigned i = 0; i < h->noutputs; i++)
		arflex_port_destroy(&h->outputs[i]);
	h->noutputs = 0;
	arflex_mailbox_deinit(&h->mb);
out_ctl:
	arflex_sys_munmap(h->ctl, ARFLEX_CTL_SIZE);
	arflex_sys_shm_unlink(h->ctl_name);
	h->ctl = NULL;
	return r;
}

static int reap(struct arflex_host *h, bool block)
{
	int st = 0, r;

	if (!h->pid || h->reaped)
		return 1;
	r = arflex_sys_waitpid(h->pid, &st, block ? 0 : WNOHANG);
	if (r == h->pid || r == -ECHILD) {
		h->exit_status = r == h->pid ? st : 0;
		h->reaped = true;
		return 1;
	}
	return 0;
}

int arflex_host_wait_exit(struct arflex_host *h, uint64_t timeout_ns)
{
	uint64_t deadline = arflex_sys_now_ns() + timeout_ns;

	if (!h->pid)
		return -ECHILD;
	while (!reap(h, false)) {
		if (arflex_sys_now_ns() > deadline)
			return -ETIMEDOUT;
		arflex_sys_sleep_until(arflex_sys_now_ns() + 500000u);
	}
	return 0;
}

void arflex_host_drop_supervisor(struct arflex_host *h)
{
	if (h->sup_open) {
		arflex_sys_close(h->sup_fd);
		h->sup_open = false;
	}
}

int arflex_host_output_fd(const struct arflex_host *h)
{
	return h->out_open ? h->out_fd : -1;
}

void arflex_host_close_output(struct arflex_host *h)
{
	if (h->out_open) {
		arflex_sys_close(h->out_fd);
		h->out_open = false;
	}
}

void arflex_host_destroy(struct arflex_host *h)
{
	if (h->pid && !h->reaped) {
		arflex_sys_kill(h->pid, SIGTERM);
		if (arflex_host_wait_exit(h, 2000000000u)) {
			arflex_sys_kill(h->pid, SIGKILL);
			reap(h, true);
		}
	}
	/* the child is gone: only now may its supervisor pipe close */
	arflex_host_drop_supervisor(h);
	arflex_host_close_output(h);
	for (unsigned i = 0; i < h->noutputs; i++)
		arflex_port_destroy(&h->outputs[i]);
	h->noutputs = 0;
	if (h->has_state)
		arflex_port_destroy(&h->state);
	h->has_state = false;
	if (h->mb.tx_name[0])
		arflex_mailbox_deinit(&h->mb);
	if (h->ctl) {
		arflex_sys_munmap(h->ctl, ARFLEX_CTL_SIZE);
		arflex_sys_shm_unlink(h->ctl_name);
		h->ctl = NULL;
	}
}

/* A fresh token for the next child, written as the first 8 bytes (little endian) into its
 * supervisor pipe while we still hold both ends (ABI.md 6.2). */
static int send_token(struct arflex_host *h, int fd)
{
	uint8_t le[8];
	uint64_t t;
	int r;

	do {
		r = arflex_sys_random(&t, sizeof(t));
	} while (!r && !t); /* 0 is the token of hosts without the pipe */
	if (r)
		return r;
	for (unsigned i = 0; i < 8; i++)
		le[i] = (uint8_t)(t >> (8 * i));
	r = arflex_sys_write_all(fd, le, sizeof(le));
	if (!r)
		h->token = t;
	return r;
}

int arflex_host_spawn(struct arflex_host *h, const char *exe, char *const extra[],
		      char *const envp[])
{
	return arflex_host_spawn_ex(h, exe, extra, envp, 0);
}

int arflex_host_spawn_ex(struct arflex_host *h, const char *exe, char *const extra[],
			 char *const envp[], unsigned flags)
{
	int sup[2] = { -1, -1 }, out[2] = { -1, -1 }, fds[3] = { -1, -1, -1 };
	char *argv[40];
	unsigned n = 0;
	int r;

	if (!h->ctl || (h->pid && !h->reaped))
		return -EINVAL;
	argv[n++] = (char *)exe;
	argv[n++] = (char *)"--runtime";
	argv[n++] = h->runtime;
	argv[n++] = (char *)"--instance";
	argv[n++] = h->instance;
	for (unsigned i = 0; extra && extra[i]; i++) {
		if (n >= 39)
			return -E2BIG;
		argv[n++] = extra[i];
	}
	argv[n] = NULL;
	/* a respawn: the pipes of the previous child (reaped) go */
	arflex_host_drop_supervisor(h);
	arflex_host_close_output(h);
	h->token = 0;
	if (flags & ARFLEX_HOST_SUPERVISOR_PIPE) {
		r = arflex_sys_pipe(sup);
		if (r)
			return r;
		fds[0] = sup[0];
		r = send_token(h, sup[1]);
		if (r)
			goto out_sup;
	}
	if (flags & ARFLEX_HOST_OUTPUT_PIPE) {
		r = arflex_sys_pipe(out);
		if (r)
			goto out_sup;
		fds[1] = fds[2] = out[1];
	}
	if (flags & ARFLEX_HOST_SUPERVISOR_PIPE)
		h->ctl->config.cfg_flags |= ARFLEX_CFG_SUPERVISOR_PIPE;
	else
		h->ctl->config.cfg_flags &= ~(uint32_t)ARFLEX_CFG_SUPERVISOR_PIPE;
	arflex_host_heartbeat(h);
	h->reaped = false;
	h->exit_status = 0;
	r = arflex_sys_spawn_io(&h->pid, exe, argv, envp, fds);
	if (r) {
		h->pid = 0;
		goto out_out;
	}
	/* the child's ends are the child's alone */
	if (flags & ARFLEX_HOST_SUPERVISOR_PIPE) {
		arflex_sys_close(sup[0]);
		h->sup_fd = sup[1];
		h->sup_open = true;
	}
	if (flags & ARFLEX_HOST_OUTPUT_PIPE) {
		arflex_sys_close(out[1]);
		h->out_fd = out[0];
		h->out_open = true;
	}
	return 0;

out_out:
	if (out[0] >= 0) {
		arflex_sys_close(out[0]);
		arflex_sys_close(out[1]);
	}
out_sup:
	if (sup[0] >= 0) {
		arflex_sys_close(sup[0]);
		arflex_sys_close(sup[1]);
	}
	return r;
}

int arflex_host_wait_state(struct arflex_host *h, uint32_t state, uint64_t timeout_ns)
{
	uint64_t deadline = arflex_sys_now_ns() + timeout_ns;

	for (;;) {
		if (arflex_ctl_state(h->ctl) == state)
			return 0;
		if (h->pid && reap(h, false))
			return arflex_ctl_state(h->ctl) == state ? 0 : -ECHILD;
		if (arflex_sys_now_ns() > deadline)
			return -ETIMEDOUT;
		arflex_sys_sleep_until(arflex_sys_now_ns() + 200000u);
	}
}

int arflex_host_exit_status(const struct arflex_host *h)
{
	return h->exit_status;
}

int arflex_host_kill(struct arflex_host *h, int sig)
{
	if (!h->pid || h->reaped)
		return -ESRCH;
	return arflex_sys_kill(h->pid, sig);
}

void arflex_host_heartbeat(struct arflex_host *h)
{
	if (h->ctl)
		arflex_ctl_set_runtime_hb(h->ctl, arflex_sys_now_ns());
}

int arflex_host_call(struct arflex_host *h, uint16_t cmd, const struct arflex_msg *req,
		     struct arflex_msg *rsp, uint64_t timeout_ns)
{
	struct arflex_msg m, r;

	if (req)
		m = *req;
	else
		memset(&m, 0, sizeof(m));
	m.magic = ARFLEX_MSG_MAGIC;
	m.abi_major = ARFLEX_ABI_MAJOR;
	m.abi_minor = ARFLEX_ABI_MINOR;
	m.cmd = cmd;
	m.flags = 0;
	m.status = 0;
	m.seq = ++h->seq;
	m.token = h->token;
	return arflex_mailbox_call(&h->mb, &m, rsp ? rsp : &r, timeout_ns);
}

int arflex_host_start(struct arflex_host *h, uint64_t timeout_ns)
{
	return arflex_host_call(h, ARFLEX_CMD_START, NULL, NULL, timeout_ns);
}

int arflex_host_stop(struct arflex_host *h, uint64_t timeout_ns)
{
	return arflex_host_call(h, ARFLEX_CMD_STOP, NULL, NULL, timeout_ns);
}

int arflex_host_shutdown(struct arflex_host *h, uint64_t timeout_ns)
{
	return arflex_host_call(h, ARFLEX_CMD_SHUTDOWN, NULL, NULL, timeout_ns);
}

int arflex_host_reset(struct arflex_host *h, uint64_t timeout_ns)
{
	return arflex_host_call(h, ARFLEX_CMD_RESET, NULL, NULL, timeout_ns);
}

static int param_call(struct arflex_host *h, uint16_t cmd, const char *name, uint64_t bits,
		      uint64_t *out, uint64_t timeout_ns)
{
	struct arflex_msg m, r;
	int st;

	if (!name || strlen(name) >= ARFLEX_NAME_SIZE)
		return -EINVAL;
	memset(&m, 0, sizeof(m));
	m.u.param.index = UINT32_MAX;
	m.u.param.value = bits;
	strcpy(m.u.param.name, name);
	m.payload_len = sizeof(m.u.param);
	st = arflex_host_call(h, cmd, &m, &r, timeout_ns);
	if (!st && out)
		*out = r.u.param.value;
	return st;
}

int arflex_host_set_param(struct arflex_host *h, const char *name, uint64_t bits,
			  uint64_t *applied, uint64_t timeout_ns)
{
	return param_call(h, ARFLEX_CMD_SET_PARAM, name, bits, applied, timeout_ns);
}

int arflex_host_get_param(struct arflex_host *h, const char *name, uint64_t *bits,
			  uint64_t timeout_ns)
{
	return param_call(h, ARFLEX_CMD_GET_PARAM, name, 0, bits, timeout_ns);
}

static int bind_call(struct arflex_host *h, uint16_t cmd, const char *port, const char *shm,
		     uint64_t timeout_ns)
{
	struct arflex_msg m;

	if (!port || strlen(port) >= ARFLEX_NAME_SIZE ||
	    (shm && strlen(shm) >= ARFLEX_OBJ_NAME_SIZE))
		return -EINVAL;
	memset(&m, 0, sizeof(m));
	strcpy(m.u.bind.port, port);
	if (shm)
		strcpy(m.u.bind.shm_name, shm);
	m.payload_len = sizeof(m.u.bind);
	return arflex_host_call(h, cmd, &m, NULL, timeout_ns);
}

int arflex_host_bind(struct arflex_host *h, const char *port, const char *shm_name,
		     uint64_t timeout_ns)
{
	if (!shm_name)
		return -EINVAL;
	return bind_call(h, ARFLEX_CMD_BIND, port, shm_name, timeout_ns);
}

int arflex_host_unbind(struct arflex_host *h, const char *port, uint64_t timeout_ns)
{
	return bind_call(h, ARFLEX_CMD_UNBIND, port, NULL, timeout_ns);
}

int arflex_host_adopt(struct arflex_host *h, const char *shm_name, uint64_t timeout_ns)
{
	if (!shm_name)
		return -EINVAL;
	return bind_call(h, ARFLEX_CMD_ADOPT, "", shm_name, timeout_ns);
}

int arflex_host_readopt(struct arflex_host *h, const char *shm_name, uint64_t timeout_ns)
{
	if (!shm_name || !shm_name[0])
		return -EINVAL;
	return bind_call(h, ARFLEX_CMD_READOPT, "", shm_name, timeout_ns);
}

struct arflex_port *arflex_host_state(struct arflex_host *h)
{
	return h->has_state ? &h->state : NULL;
}

const char *arflex_host_output_name(const struct arflex_host *h, const char *port)
{
	for (unsigned i = 0; i < h->noutputs; i++)
		if (!strcmp(h->output_ports[i], port))
			return h->outputs[i].name;
	return NULL;
}

struct arflex_port *arflex_host_output(struct arflex_host *h, const char *port)
{
	for (unsigned i = 0; i < h->noutputs; i++)
		if (!strcmp(h->output_ports[i], port))
			return &h->outputs[i];
	return NULL;
}
