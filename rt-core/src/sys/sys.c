/* The thin POSIX wrapper layer with its fault-injection hook. See arflex/sys.h. */
#include "arflex/sys.h"

#include <errno.h>
#include <fcntl.h>
#include <sched.h>
#include <spawn.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

extern char **environ;

static long fault_nth;       /* 0: off */
static int fault_err;
static long fault_calls;
static int fault_fired;
static int fault_env_done;

void arflex_sys_fault_set(long nth, int err)
{
	__atomic_store_n(&fault_env_done, 1, __ATOMIC_RELAXED);
	__atomic_store_n(&fault_calls, 0, __ATOMIC_RELAXED);
	__atomic_store_n(&fault_fired, 0, __ATOMIC_RELAXED);
	__atomic_store_n(&fault_err, err, __ATOMIC_RELAXED);
	__atomic_store_n(&fault_nth, nth, __ATOMIC_RELEASE);
}

long arflex_sys_fault_calls(void)
{
	return __atomic_load_n(&fault_calls, __ATOMIC_RELAXED);
}

bool arflex_sys_fault_fired(void)
{
	return __atomic_load_n(&fault_fired, __ATOMIC_RELAXED) != 0;
}

bool arflex_sys_test_hooks(void)
{
	const char *m = getenv("ARFLEX_TEST_HOOKS");

	return m && !strcmp(m, "1");
}

const char *arflex_sys_fault_env(const char *name)
{
	return arflex_sys_test_hooks() ? getenv(name) : NULL;
}

static void fault_env(void)
{
	const char *s, *e;
	char *end;
	long n;

	if (__atomic_exchange_n(&fault_env_done, 1, __ATOMIC_ACQ_REL))
		return;
	s = arflex_sys_fault_env("ARFLEX_FAULT_NTH");
	if (!s || !*s)
		return;
	n = strtol(s, &end, 10);
	if (*end || n < 0)
		return;
	e = arflex_sys_fault_env("ARFLEX_FAULT_ERRNO");
	__atomic_store_n(&fault_err, e ? atoi(e) : 0, __ATOMIC_RELAXED);
	__atomic_store_n(&fault_nth, n, __ATOMIC_RELEASE);
}

/* Returns 0 to proceed, or the -errno to fail this call with. */
static int fault(int dflt)
{
	long nth, c;
	int err;

	if (!__atomic_load_n(&fault_env_done, __ATOMIC_ACQUIRE))
		fault_env();
	nth = __atomic_load_n(&fault_nth, __ATOMIC_ACQUIRE);
	if (nth <= 0)
		return 0;
	c = __atomic_add_fetch(&fault_calls, 1, __ATOMIC_RELAXED);
	if (c != nth)
		return 0;
	__atomic_store_n(&fault_fired, 1, __ATOMIC_RELAXED);
	err = __atomic_load_n(&fault_err, __ATOMIC_RELAXED);
	return -(err > 0 ? err : dflt);
}

uint64_t arflex_sys_now_ns(void)
{
	struct timespec ts;

	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec;
}

struct timespec arflex_sys_ts(uint64_t ns)
{
	struct timespec ts;

	ts.tv_sec = (time_t)(ns / 1000000000u);
	ts.tv_nsec = (long)(ns % 1000000000u);
	return ts;
}

int arflex_sys_sleep_until(uint64_t deadline_ns)
{
	struct timespec ts = arflex_sys_ts(deadline_ns);
	int r;

	do {
		r = clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL);
	} while (r == EINTR);
	return -r;
}

struct timespec arflex_sys_realtime_in(uint64_t rel_ns)
{
	struct timespec ts;
	uint64_t ns;

	clock_gettime(CLOCK_REALTIME, &ts);
	ns = (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec + rel_ns;
	return arflex_sys_ts(ns);
}

/*
 * /dev/shm is writable by every user (issue 30, D79): an object is only used when it is a
 * regular file of this process's user. glibc's shm_open adds O_NOFOLLOW; O_NONBLOCK keeps a
 * FIFO someone put at the name from blocking the open (it changes nothing for a regular file).
 */
int arflex_sys_shm_open(const char *name, int oflag, mode_t mode)
{
	struct stat st;
	int r = fault(EMFILE);

	if (r)
		return r;
	do {
		r = shm_open(name, oflag | O_NONBLOCK, mode);
	} while (r < 0 && errno == EINTR);
	if (r < 0)
		return -errno;
	if (fstat(r, &st) || !S_ISREG(st.st_mode) || st.st_uid != geteuid()) {
		close(r);
		return -EPERM;
	}
	return r;
}

int arflex_sys_shm_unlink(const char *name)
{
	return shm_unlink(name) ? -errno : 0;
}

int arflex_sys_open(const char *path, int oflag, mode_t mode)
{
	int r = fault(EMFILE);

	if (r)
		return r;
	do {
		r = open(path, oflag, mode);
	} while (r < 0 && errno == EINTR);
	return r < 0 ? -errno : r;
}

int arflex_sys_close(int fd)
{
	if (fd < 0)
		return -EBADF;
	/* Linux releases the descriptor even when close() reports EINTR: never retry. */
	if (close(fd) && errno != EINTR)
		return -errno;
	return 0;
}

int arflex_sys_ftruncate(int fd, off_t len)
{
	int r = fault(ENOSPC);

	if (r)
		return r;
	do {
		r = ftruncate(fd, len);
	} while (r < 0 && errno == EINTR);
	return r < 0 ? -errno : 0;
}

int arflex_sys_fstat(int fd, struct stat *st)
{
	int r = fault(EIO);

	if (r)
		return r;
	return fstat(fd, st) ? -errno : 0;
}

int arflex_sys_write_all(int fd, const void *buf, size_t len)
{
	const char *p = buf;
	ssize_t n;
	int r = fault(EIO);

	if (r)
		return r;
	while (len) {
		n = write(fd, p, len);
		if (n < 0) {
			if (errno == EINTR)
				continue;
			return -errno;
		}
		p += n;
		len -= (size_t)n;
	}
	return 0;
}

long arflex_sys_read(int fd, void *buf, size_t len)
{
	ssize_t n;
	int r = fault(EIO);

	if (r)
		return r;
	do {
		n = read(fd, buf, len);
	} while (n < 0 && errno == EINTR);
	return n < 0 ? -errno : (long)n;
}

int arflex_sys_random(void *buf, size_t len)
{
	uint8_t *p = buf;

	while (len) {
		ssize_t n = getrandom(p, len, 0);

		if (n < 0 && errno == EINTR)
			continue;
		if (n < 0)
			return -errno;
		p += n;
		len -= (size_t)n;
	}
	return 0;
}

int arflex_sys_pipe(int fds[2])
{
	int r = fault(EMFILE);

	if (r)
		return r;
	return pipe2(fds, O_CLOEXEC) ? -errno : 0;
}

int arflex_sys_nonblock_pipe(int fd)
{
	struct stat st;
	int fl;

	if (fstat(fd, &st))
		return -errno;
	if (!S_ISFIFO(st.st_mode))
		return 0;
	fl = fcntl(fd, F_GETFL);
	if (fl < 0 || fcntl(fd, F_SETFL, fl | O_NONBLOCK))
		return -errno;
	return 1;
}

int arflex_sys_mmap(void **out, size_t len, int prot, int flags, int fd, off_t off)
{
	void *p;
	int r = fault(ENOMEM);

	if (r)
		return r;
	p = mmap(NULL, len, prot, flags, fd, off);
	if (p == MAP_FAILED)
		return -errno;
	*out = p;
	return 0;
}

int arflex_sys_munmap(void *addr, size_t len)
{
	return munmap(addr, len) ? -errno : 0;
}

int arflex_sys_mlockall(int flags)
{
	int r = fault(ENOMEM);

	if (r)
		return r;
	return mlockall(flags) ? -errno : 0;
}

int arflex_sys_munlockall(void)
{
	return munlockall() ? -errno : 0;
}

int arflex_sys_mq_open(mqd_t *out, const char *name, int oflag, mode_t mode,
		       struct mq_attr *attr)
{
	mqd_t q;
	int r = fault(EMFILE);

	if (r)
		return r;
	do {
		q = (oflag & O_CREAT) ? mq_open(name, oflag, mode, attr) : mq_open(name, oflag);
	} while (q == (mqd_t)-1 && errno == EINTR);
	if (q == (mqd_t)-1)
		return -errno;
	*out = q;
	return 0;
}

int arflex_sys_mq_close(mqd_t q)
{
	return mq_close(q) ? -errno : 0;
}

int arflex_sys_mq_unlink(const char *name)
{
	return mq_unlink(name) ? -errno : 0;
}

int arflex_sys_mq_getattr(mqd_t q, struct mq_attr *attr)
{
	int r = fault(EBADF);

	if (r)
		return r;
	return mq_getattr(q, attr) ? -errno : 0;
}

/* The mq timeouts are absolute, so retrying after EINTR keeps the same deadline. */
int arflex_sys_mq_timedsend(mqd_t q, const void *msg, size_t len,
			    const struct timespec *abs_realtime)
{
	int r = fault(EAGAIN);

	if (r)
		return r;
	do {
		r = abs_realtime ? mq_timedsend(q, msg, len, 0, abs_realtime)
				 : mq_send(q, msg, len, 0);
	} while (r < 0 && errno == EINTR);
	return r < 0 ? -errno : 0;
}

long arflex_sys_mq_timedreceive(mqd_t q, void *buf, size_t len,
				const struct timespec *abs_realtime)
{
	ssize_t n;
	int r = fault(EAGAIN);

	if (r)
		return r;
	do {
		n = abs_realtime ? mq_timedreceive(q, buf, len, NULL, abs_realtime)
				 : mq_receive(q, buf, len, NULL);
	} while (n < 0 && errno == EINTR);
	return n < 0 ? -errno : (long)n;
}

int arflex_sys_thread_create(pthread_t *t, const pthread_attr_t *attr, void *(*fn)(void *),
			     void *arg)
{
	int r = fault(EAGAIN);

	if (r)
		return r;
	return -pthread_create(t, attr, fn, arg);
}

int arflex_sys_thread_join(pthread_t t, void **ret)
{
	return -pthread_join(t, ret);
}

int arflex_sys_set_sched(int policy, int priority)
{
	struct sched_param sp = { .sched_priority = priority };
	int r = fault(EPERM);

	if (r)
		return r;
	return -pthread_setschedparam(pthread_self(), policy, &sp);
}

int arflex_sys_set_affinity(uint64_t mask)
{
	cpu_set_t set;
	int r = fault(EINVAL);

	if (r)
		return r;
	CPU_ZERO(&set);
	for (int i = 0; i < 64; i++)
		if (mask & (UINT64_C(1) << i))
			CPU_SET(i, &set);
	return -pthread_setaffinity_np(pthread_self(), sizeof(set), &set);
}

int arflex_sys_spawn(pid_t *pid, const char *path, char *const argv[], char *const envp[])
{
	int r = fault(EAGAIN);

	if (r)
		return r;
	return -posix_spawn(pid, path, NULL, NULL, argv, envp ? envp : environ);
}

int arflex_sys_spawn_io(pid_t *pid, const char *path, char *const argv[], char *const envp[],
			const int fds[3])
{
	posix_spawn_file_actions_t fa;
	int r = fault(EAGAIN);

	if (r)
		return r;
	r = posix_spawn_file_actions_init(&fa);
	if (r)
		return -r;
	for (int i = 0; i < 3 && !r; i++)
		if (fds[i] >= 0)
			r = posix_spawn_file_actions_adddup2(&fa, fds[i], i);
	if (!r)
		r = posix_spawn(pid, path, &fa, NULL, argv, envp ? envp : environ);
	posix_spawn_file_actions_destroy(&fa);
	return -r;
}

int arflex_sys_kill(pid_t pid, int sig)
{
	return kill(pid, sig) ? -errno : 0;
}

int arflex_sys_waitpid(pid_t pid, int *status, int options)
{
	pid_t r;

	do {
		r = waitpid(pid, status, options);
	} while (r < 0 && errno == EINTR);
	return r < 0 ? -errno : (int)r;
}
