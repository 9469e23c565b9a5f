/*
 * arflex/sys.h - the one thin POSIX wrapper layer of rt-core.
 *
 * Every system call rt-core makes goes through these wrappers. Each wrapper:
 *   - returns 0 (or a non-negative result such as a file descriptor or a byte count) on
 *     success and a NEGATIVE errno on failure, whatever the convention of the wrapped call
 *     (calls that return the error such as clock_nanosleep and pthread_* are handled as well as
 *     calls that set errno such as shm_open, mmap, mq_send);
 *   - retries on EINTR where retrying is correct (never for calls with a relative timeout);
 *   - for ACQUIRING calls (open, create, map, spawn, send, receive, scheduling changes) passes
 *     through the fault-injection hook. RELEASING calls (close, munmap, unlink, join, kill,
 *     waitpid) are never failed on purpose, so that cleanup paths can be checked for leaks.
 *
 * Fault injection: compiled in always, inert unless enabled. When enabled with N > 0, the N-th
 * acquiring call after enabling fails with the given errno (or a realistic default for that
 * call) and no side effect; all other calls behave normally. It is enabled either by
 * arflex_sys_fault_set() or, at the first wrapped call of a process, by the environment
 * variable ARFLEX_FAULT_NTH=<N> (optionally ARFLEX_FAULT_ERRNO=<errno number>), which is read
 * only when the environment also holds the test-hook marker ARFLEX_TEST_HOOKS=1 (D80: only a
 * test runtime's DRCR and the tests set it; a production half ignores every ARFLEX_FAULT_*).
 * The counter is per process and thread safe.
 *
 * Thread safety: all functions are thread safe. arflex_sys_now_ns() and
 * arflex_sys_sleep_until() are safe on the RT thread (no allocation, no lock).
 */
#ifndef ARFLEX_SYS_H
#define ARFLEX_SYS_H

#include <mqueue.h>
#include <pthread.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <time.h>

#ifdef __cplusplus
extern "C" {
#endif

#if defined(ARFLEX_BUILDING_LIB)
#define ARFLEX_API __attribute__((visibility("default")))
#else
#define ARFLEX_API
#endif

#ifdef __cplusplus
#define ARFLEX_STATIC_ASSERT(c, m) static_assert(c, m)
#else
#define ARFLEX_STATIC_ASSERT(c, m) _Static_assert(c, m)
#endif

/* ---- fault injection ---------------------------------------------------------------- */

/**
 * Enables fault injection: the @nth acquiring wrapped call from now on fails with -@err
 * (@err == 0: a realistic errno for that call, e.g. EMFILE for opens, ENOMEM for mmap).
 * @nth == 0 disables injection. Resets the call counter.
 */
ARFLEX_API void arflex_sys_fault_set(long nth, int err);

/** Number of acquiring wrapped calls made since the last arflex_sys_fault_set(). */
ARFLEX_API long arflex_sys_fault_calls(void);

/** True when an injected fault has fired since the last arflex_sys_fault_set(). */
ARFLEX_API bool arflex_sys_fault_fired(void);

/** True when this process's environment holds the test-hook marker ARFLEX_TEST_HOOKS=1 (D80). */
ARFLEX_API bool arflex_sys_test_hooks(void);

/**
 * The value of the test fault variable @name (an ARFLEX_FAULT_*), or NULL when it is unset or
 * the test-hook marker is not (arflex_sys_test_hooks()): a production half has no fault mode.
 * Not for the RT thread (getenv).
 */
ARFLEX_API const char *arflex_sys_fault_env(const char *name);

/* ---- time (never faulted, RT safe) -------------------------------------------------- */

/** CLOCK_MONOTONIC now, in nanoseconds. */
ARFLEX_API uint64_t arflex_sys_now_ns(void);

/** Converts nanoseconds to a timespec. */
ARFLEX_API struct timespec arflex_sys_ts(uint64_t ns);

/** Absolute-time clock_nanosleep on CLOCK_MONOTONIC until @deadline_ns; retries EINTR.
 *  Returns 0 or -errno. */
ARFLEX_API int arflex_sys_sleep_until(uint64_t deadline_ns);

/* ---- shared memory and files -------------------------------------------------------- */

/** shm_open(). Returns a file descriptor or -errno. */
ARFLEX_API int arflex_sys_shm_open(const char *name, int oflag, mode_t mode);
/** shm_unlink(). Returns 0 or -errno (never faulted). */
ARFLEX_API int arflex_sys_shm_unlink(const char *name);
/** open(). Returns a file descriptor or -errno. */
ARFLEX_API int arflex_sys_open(const char *path, int oflag, mode_t mode);
/** close(). Returns 0 or -errno (never faulted; EINTR is not retried, as on Linux the fd is
 *  released anyway). */
ARFLEX_API int arflex_sys_close(int fd);
/** ftruncate(). Returns 0 or -errno. */
ARFLEX_API int arflex_sys_ftruncate(int fd, off_t len);
/** fstat(). Returns 0 or -errno. */
ARFLEX_API int arflex_sys_fstat(int fd, struct stat *st);
/** write() of the whole buffer (loops on short writes). Returns 0 or -errno. */
ARFLEX_API int arflex_sys_write_all(int fd, const void *buf, size_t len);
/** read(); retries EINTR. Returns the byte count (0 at EOF) or -errno. */
ARFLEX_API long arflex_sys_read(int fd, void *buf, size_t len);
/** Fills @buf with @len random bytes from getrandom() (blocks until the pool is ready).
 *  Returns 0 or -errno. */
ARFLEX_API int arflex_sys_random(void *buf, size_t len);
/** pipe2(O_CLOEXEC): @fds[0] the read end, @fds[1] the write end. Returns 0 or -errno. */
ARFLEX_API int arflex_sys_pipe(int fds[2]);
/** Sets O_NONBLOCK on @fd when it is a pipe or FIFO (never on a TTY or a file). Returns 1 if
 *  set, 0 if @fd is not a pipe, or -errno (never faulted). */
ARFLEX_API int arflex_sys_nonblock_pipe(int fd);
/** mmap(). Stores the mapping in *@out. Returns 0 or -errno. */
ARFLEX_API int arflex_sys_mmap(void **out, size_t len, int prot, int flags, int fd, off_t off);
/** munmap(). Returns 0 or -errno (never faulted). */
ARFLEX_API int arflex_sys_munmap(void *addr, size_t len);
/** mlockall(). Returns 0 or -errno. */
ARFLEX_API int arflex_sys_mlockall(int flags);
/** munlockall(). Returns 0 or -errno (never faulted). */
ARFLEX_API int arflex_sys_munlockall(void);

/* ---- message queues ----------------------------------------------------------------- */

/** mq_open(). Stores the descriptor in *@out. @attr may be NULL. Returns 0 or -errno. */
ARFLEX_API int arflex_sys_mq_open(mqd_t *out, const char *name, int oflag, mode_t mode,
				  struct mq_attr *attr);
/** mq_close(). Returns 0 or -errno (never faulted). */
ARFLEX_API int arflex_sys_mq_close(mqd_t q);
/** mq_unlink(). Returns 0 or -errno (never faulted). */
ARFLEX_API int arflex_sys_mq_unlink(const char *name);
/** mq_getattr(). Returns 0 or -errno. */
ARFLEX_API int arflex_sys_mq_getattr(mqd_t q, struct mq_attr *attr);
/** mq_timedsend() with an absolute CLOCK_REALTIME deadline (NULL: block). Returns 0 or
 *  -errno (-ETIMEDOUT on expiry). */
ARFLEX_API int arflex_sys_mq_timedsend(mqd_t q, const void *msg, size_t len,
				       const struct timespec *abs_realtime);
/** mq_timedreceive(). Returns the message length or -errno (-ETIMEDOUT on expiry). */
ARFLEX_API long arflex_sys_mq_timedreceive(mqd_t q, void *buf, size_t len,
					   const struct timespec *abs_realtime);
/** An absolute CLOCK_REALTIME timespec @rel_ns from now, for the mq timeouts. */
ARFLEX_API struct timespec arflex_sys_realtime_in(uint64_t rel_ns);

/* ---- threads, scheduling, processes ------------------------------------------------- */

/** pthread_create(). Returns 0 or -errno. */
ARFLEX_API int arflex_sys_thread_create(pthread_t *t, const pthread_attr_t *attr,
					void *(*fn)(void *), void *arg);
/** pthread_join(). Returns 0 or -errno (never faulted). */
ARFLEX_API int arflex_sys_thread_join(pthread_t t, void **ret);
/** pthread_setschedparam() on the calling thread. Returns 0 or -errno. */
ARFLEX_API int arflex_sys_set_sched(int policy, int priority);
/** pthread_setaffinity_np() of the calling thread to the CPUs set in @mask (bit i = CPU i).
 *  Returns 0 or -errno. */
ARFLEX_API int arflex_sys_set_affinity(uint64_t mask);
/** posix_spawn() of @path with @argv and @envp (NULL: the current environment). Returns 0 and
 *  the pid in *@pid, or -errno. */
ARFLEX_API int arflex_sys_spawn(pid_t *pid, const char *path, char *const argv[],
				char *const envp[]);
/** As arflex_sys_spawn(), with the child's fd i (0 stdin, 1 stdout, 2 stderr) duplicated from
 *  @fds[i] when @fds[i] >= 0 (inherited otherwise). */
ARFLEX_API int arflex_sys_spawn_io(pid_t *pid, const char *path, char *const argv[],
				   char *const envp[], const int fds[3]);
/** kill(). Returns 0 or -errno (never faulted). */
ARFLEX_API int arflex_sys_kill(pid_t pid, int sig);
/** waitpid(); retries EINTR. Returns the pid, 0 (WNOHANG, still running) or -errno (never
 *  faulted). */
ARFLEX_API int arflex_sys_waitpid(pid_t pid, int *status, int options);

#ifdef __cplusplus
}
#endif
#endif /* ARFLEX_SYS_H */
