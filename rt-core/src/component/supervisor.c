/* The supervisor's death and the orphan policy of an RT half (ABI.md 6.2, DECISIONS.md D10):
 * a watcher thread takes EOF on fd 0 (the supervisor's pipe) as its death; the mailbox thread
 * then holds safe mode for config.orphan_hold_ns, leaves as on SHUTDOWN and removes the
 * instance's own objects, since no manager is left to do it. */
#include "internal.h"

#include <errno.h>
#include <poll.h>
#include <signal.h>

#define TOKEN_WAIT_NS 5000000000u /* the manager writes the token right at the spawn */
#define ORPHAN_SAFE_WAIT_NS 1000000000u /* after the hold: wait this long at most for the
					 * RT thread's first safe cycle of the orphan */

/* The orphan policy (ABI.md 6.2): once the watcher saw the supervisor go, safe mode holds
 * (the RT thread enters it within a cycle; when not running the flags say so too) for
 * config.orphan_hold_ns from the loss, and at least one safe cycle has run if running; then
 * true: the half leaves as on SHUTDOWN and removes its own objects. */
bool arflex_comp_orphan_done(struct arflex_component *c)
{
	struct arflex_ctl *ctl = c->ctl;
	uint64_t lost = LOAD(&c->lost_ns), hold = ctl->config.orphan_hold_ns, now;

	if (!lost)
		return false;
	if (!c->lost_noticed) {
		c->lost_noticed = true;
		arflex_comp_log(c, "supervisor lost (EOF on its pipe): safe mode, holding %llu ms, then "
		      "exiting and removing my objects", (unsigned long long)(hold / 1000000u));
	}
	if (!c->running) {
		if (ctl->config.cfg_flags & ARFLEX_CFG_MOVES_HARDWARE)
			__atomic_or_fetch(&ctl->flags, ARFLEX_FLAG_RESET_REQUIRED,
					  __ATOMIC_RELEASE);
		__atomic_or_fetch(&ctl->flags, ARFLEX_FLAG_SAFE_ACTIVE, __ATOMIC_RELEASE);
	}
	now = arflex_sys_now_ns();
	if (now - lost < hold)
		return false;
	if (c->running && !LOAD(&c->orphan_safe) && now - lost < hold + ORPHAN_SAFE_WAIT_NS)
		return false;
	return true;
}

/* Waits until fd 0 is readable or @deadline (monotonic ns) passed. Returns 0 or -errno. */
static int wait_readable(uint64_t deadline)
{
	for (;;) {
		struct pollfd p = { .fd = 0, .events = POLLIN };
		uint64_t now = arflex_sys_now_ns();
		int r;

		if (now >= deadline)
			return -ETIMEDOUT;
		r = poll(&p, 1, (int)((deadline - now) / 1000000u) + 1);
		if (r > 0)
			return 0;
		if (r < 0 && errno != EINTR)
			return -errno;
	}
}

/* The manager's mailbox token (ABI.md 5, 6.2; DECISIONS.md D13): the first 8 bytes on the
 * supervisor pipe, little endian, read on the main thread before the watcher starts and
 * before any request is served. Returns 0 or -errno (-ETIMEDOUT, -EPIPE: EOF, -EPROTO: 0). */
int arflex_comp_read_token(struct arflex_component *c)
{
	uint64_t deadline = arflex_sys_now_ns() + TOKEN_WAIT_NS, t = 0;
	uint8_t le[8];
	size_t got = 0;

	while (got < sizeof(le)) {
		int r = wait_readable(deadline);
		long n;

		if (r)
			return r;
		n = arflex_sys_read(0, le + got, sizeof(le) - got);
		if (n < 0 && n != -EAGAIN)
			return (int)n;
		if (n == 0)
			return -EPIPE;
		if (n > 0)
			got += (size_t)n;
	}
	for (unsigned i = 0; i < sizeof(le); i++)
		t |= (uint64_t)le[i] << (8 * i);
	if (!t)
		return -EPROTO; /* 0 is the token of hosts without the pipe: never over it */
	c->token = t;
	return 0;
}

/* The supervisor-pipe watcher (ARFLEX_CFG_SUPERVISOR_PIPE): blocks in read() on fd 0; EOF or
 * an error means the supervisor is gone. Not the RT thread; it only sets two words. */
/* Blocks in poll() on fd 0 and on the wake pipe: EOF or an error on fd 0 means the supervisor
 * is gone; the wake pipe ends the watch without that (an orderly exit). No cancellation: a
 * thread cancelled in read() is not something every runtime (ASan's among them) unwinds. */
static void *watch_supervisor(void *arg)
{
	struct arflex_component *c = arg;
	struct pollfd fds[2] = { { .fd = 0, .events = POLLIN }, { .fd = c->watch_wake[0], .events = POLLIN } };
	char buf[64];

	for (;;) {
		if (poll(fds, 2, -1) < 0) {
			if (errno == EINTR)
				continue;
			break; /* cannot watch: take it as lost, the safe side */
		}
		if (fds[1].revents)
			return NULL; /* orderly exit */
		if (fds[0].revents) {
			long n = arflex_sys_read(0, buf, sizeof(buf)); /* data after the token: ignored */

			if (n <= 0 && n != -EINTR && n != -EAGAIN)
				break;
		}
	}
	STORE(&c->lost_ns, arflex_sys_now_ns());
	__atomic_or_fetch(&c->ctl->flags, ARFLEX_FLAG_SUPERVISOR_LOST, __ATOMIC_RELEASE);
	return NULL;
}

int arflex_comp_watch_start(struct arflex_component *c)
{
	sigset_t all, old;
	int r;

	r = arflex_sys_pipe(c->watch_wake);
	if (r)
		return r;
	sigemptyset(&all);
	sigaddset(&all, SIGTERM);
	sigaddset(&all, SIGINT);
	pthread_sigmask(SIG_BLOCK, &all, &old);
	r = arflex_sys_thread_create(&c->watcher, NULL, watch_supervisor, c);
	pthread_sigmask(SIG_SETMASK, &old, NULL);
	c->watching = !r;
	if (r) {
		arflex_sys_close(c->watch_wake[0]);
		arflex_sys_close(c->watch_wake[1]);
	}
	return r;
}

/* Before the control block is unmapped: the watcher must not write to it any more. Closing
 * the wake pipe's write end wakes it (EOF on the wake pipe); then it is joined. */
void arflex_comp_watch_stop(struct arflex_component *c)
{
	if (!c->watching)
		return;
	arflex_sys_close(c->watch_wake[1]);
	arflex_sys_thread_join(c->watcher, NULL);
	arflex_sys_close(c->watch_wake[0]);
	c->watching = false;
}

/* No manager is left to remove the objects of an orphan (ABI.md 2, DECISIONS.md D10). */
void arflex_comp_unlink_own(struct arflex_component *c, unsigned noutputs)
{
	char name[ARFLEX_OBJ_NAME_SIZE];

	for (unsigned i = 0; i < noutputs; i++)
		if (!arflex_comp_output_obj_name(c, c->output_names[i], name, sizeof(name)))
			arflex_sys_shm_unlink(name);
	if (!arflex_ctl_obj_name(name, sizeof(name), c->rid, c->inst, "state"))
		arflex_sys_shm_unlink(name); /* the state block (D41), if the manager made one */
	if (!arflex_ctl_obj_name(name, sizeof(name), c->rid, c->inst, "cmd"))
		arflex_sys_mq_unlink(name);
	if (!arflex_ctl_obj_name(name, sizeof(name), c->rid, c->inst, "rsp"))
		arflex_sys_mq_unlink(name);
	arflex_sys_shm_unlink(c->ctl_name);
}
