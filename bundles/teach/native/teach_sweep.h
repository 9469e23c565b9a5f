/* teach_sweep - removing the recording journals of teach halves that are gone (docs/DECISIONS.md
 * D63; the journal itself: teach_rec.h, D57).
 *
 * A teach half keeps its recording in <data>/teach-rec-<pid>-<nonce>.bin and removes it when it
 * exits cleanly; a half killed (kill -9, a crash) leaves it behind. A running half sweeps its data
 * folder (its writer thread, once it has started and published its own state block, and whenever
 * a new recording begins): it removes a file only when all of these hold, and names in its log
 * every file named like a journal that it refuses to touch:
 *  - the name is exactly teach-rec-<pid 1..2^31-1>-<16 hex>.bin and the pid is not its own;
 *  - seen without following a link (fstatat AT_SYMLINK_NOFOLLOW on the folder's fd): a regular
 *    file of the sweeper's uid with one link (a symlink, FIFO, folder, another owner's file or a
 *    hard link is refused and left as it is);
 *  - its writer is gone: kill(pid, 0) says ESRCH (a pid that exists, whoever it is now, keeps
 *    the file: an old half kept warm in a change set's window, or one a new half is ADOPTing
 *    from, is a running process) and nobody holds the writer's lock (flock, taken by a writer
 *    right after it creates the file: a writer in another pid namespace keeps its file too);
 *  - the file opened (O_NOFOLLOW, openat) is the one looked at (same device and inode), then
 *    removed with unlinkat on the folder's fd.
 * The folder itself must be the sweeper's and not writable by group or others (else nothing is
 * swept, and the log says why). Blocking I/O: not on the RT thread.
 */
#ifndef TEACH_SWEEP_H
#define TEACH_SWEEP_H

#include <stdint.h>
#include <sys/types.h>

#ifdef __cplusplus
extern "C" {
#endif

struct teach_sweep_count {
	unsigned removed; /* journals of halves that are gone, removed */
	unsigned kept;    /* journals of running halves (their pid exists or their lock is held) */
	unsigned refused; /* named like a journal but not removable (link, owner, type, links) */
};

/** Receives one line per file removed, kept or refused (no newline). */
typedef void (*teach_sweep_log)(void *user, const char *line);

/** Whether @name is a journal's name; its pid into @pid. */
int teach_sweep_parse(const char *name, uint32_t *pid);

/**
 * Sweeps @dir as described above, as the half @own_pid of uid @uid. 0 (also for a folder that
 * does not exist) or -errno when the folder cannot be opened or is not safe to sweep (-EPERM:
 * another owner, writable by group or others; -ELOOP: a symlink); @n counts what was found.
 */
int teach_sweep(const char *dir, uint32_t own_pid, uid_t uid, teach_sweep_log log, void *user,
		struct teach_sweep_count *n);

#ifdef __cplusplus
}
#endif

#endif
