/* teach_sweep - see teach_sweep.h (docs/DECISIONS.md D63). */
#ifndef _GNU_SOURCE
#define _GNU_SOURCE
#endif
#include "teach_sweep.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#define PREFIX "teach-rec-"
#define SUFFIX ".bin"

int teach_sweep_parse(const char *name, uint32_t *pid)
{
	if (strncmp(name, PREFIX, sizeof(PREFIX) - 1) != 0)
		return 0;
	const char *p = name + sizeof(PREFIX) - 1;
	uint64_t v = 0;
	int digits = 0;
	for (; *p >= '0' && *p <= '9'; ++p, ++digits) {
		v = v * 10 + (uint64_t)(*p - '0');
		if (digits >= 10 || v > 0x7fffffffu)
			return 0;
	}
	if (digits == 0 || v == 0 || (digits > 1 && name[sizeof(PREFIX) - 1] == '0') || *p++ != '-')
		return 0;
	for (int i = 0; i < 16; ++i, ++p)
		if (!((*p >= '0' && *p <= '9') || (*p >= 'a' && *p <= 'f')))
			return 0;
	if (strcmp(p, SUFFIX) != 0)
		return 0;
	*pid = (uint32_t)v;
	return 1;
}

static void say(teach_sweep_log log, void *user, const char *fmt, ...)
	__attribute__((format(printf, 3, 4)));

static void say(teach_sweep_log log, void *user, const char *fmt, ...)
{
	char line[640];
	va_list ap;
	if (!log)
		return;
	va_start(ap, fmt);
	vsnprintf(line, sizeof(line), fmt, ap);
	va_end(ap);
	log(user, line);
}

/* One entry of the folder; counts it in @n. */
static void sweep_one(int dfd, const char *dir, const char *name, uint32_t pid, uid_t uid,
		      teach_sweep_log log, void *user, struct teach_sweep_count *n)
{
	struct stat st, fst;
	if (fstatat(dfd, name, &st, AT_SYMLINK_NOFOLLOW) != 0)
		return; /* gone meanwhile (its half exited cleanly) */
	if (S_ISLNK(st.st_mode)) {
		n->refused++;
		say(log, user, "teach: not removed: %s/%s is a symbolic link, not a journal (not followed)",
		    dir, name);
		return;
	}
	if (!S_ISREG(st.st_mode)) {
		n->refused++;
		say(log, user, "teach: not removed: %s/%s is not a regular file (mode %06o)", dir, name,
		    (unsigned)st.st_mode);
		return;
	}
	if (st.st_uid != uid) {
		n->refused++;
		say(log, user, "teach: not removed: %s/%s belongs to uid %u, not to this process (uid %u)",
		    dir, name, (unsigned)st.st_uid, (unsigned)uid);
		return;
	}
	if (st.st_nlink != 1) {
		n->refused++;
		say(log, user, "teach: not removed: %s/%s has %lu links (a journal has one)", dir, name,
		    (unsigned long)st.st_nlink);
		return;
	}
	if (kill((pid_t)pid, 0) == 0 || errno != ESRCH) {
		n->kept++;
		say(log, user, "teach: kept the journal %s/%s: its half (pid %u) is running", dir, name,
		    (unsigned)pid);
		return;
	}
	int fd = openat(dfd, name, O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
	if (fd < 0) {
		if (errno != ENOENT) {
			n->refused++;
			say(log, user, "teach: not removed: %s/%s: %s", dir, name, strerror(errno));
		}
		return;
	}
	if (fstat(fd, &fst) != 0 || fst.st_dev != st.st_dev || fst.st_ino != st.st_ino) {
		n->refused++;
		say(log, user, "teach: not removed: %s/%s changed while it was looked at", dir, name);
		close(fd);
		return;
	}
	if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
		n->kept++;
		say(log, user, "teach: kept the journal %s/%s: its writer's lock is held (pid %u is not in "
			       "this pid namespace)", dir, name, (unsigned)pid);
		close(fd);
		return;
	}
	/* the name still the file opened, then removed (without following a link) */
	if (fstatat(dfd, name, &st, AT_SYMLINK_NOFOLLOW) != 0 || st.st_dev != fst.st_dev ||
	    st.st_ino != fst.st_ino) {
		n->refused++;
		say(log, user, "teach: not removed: %s/%s changed while it was looked at", dir, name);
	} else if (unlinkat(dfd, name, 0) != 0) {
		n->refused++;
		say(log, user, "teach: not removed: %s/%s: %s", dir, name, strerror(errno));
	} else {
		n->removed++;
		say(log, user, "teach: removed the journal %s/%s of a half that is gone (pid %u, %lld bytes)",
		    dir, name, (unsigned)pid, (long long)fst.st_size);
	}
	close(fd);
}

int teach_sweep(const char *dir, uint32_t own_pid, uid_t uid, teach_sweep_log log, void *user,
		struct teach_sweep_count *n)
{
	struct stat st;
	memset(n, 0, sizeof(*n));
	int dfd = open(dir, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
	if (dfd < 0) {
		int r = errno == ENOTDIR && lstat(dir, &st) == 0 && S_ISLNK(st.st_mode) ? -ELOOP : -errno;
		if (r == -ENOENT)
			return 0;
		say(log, user, "teach: the data folder %s is not swept: %s", dir, strerror(-r));
		return r;
	}
	if (fstat(dfd, &st) != 0 || st.st_uid != uid || (st.st_mode & 022)) {
		say(log, user, "teach: the data folder %s is not swept: it belongs to uid %u (this process: "
			       "%u), mode %03o: another owner or writable by group or others", dir,
		    (unsigned)st.st_uid, (unsigned)uid, (unsigned)(st.st_mode & 0777));
		close(dfd);
		return -EPERM;
	}
	int lfd = dup(dfd);
	DIR *d = lfd < 0 ? NULL : fdopendir(lfd);
	if (!d) {
		int r = -errno;
		if (lfd >= 0)
			close(lfd);
		close(dfd);
		say(log, user, "teach: the data folder %s is not swept: %s", dir, strerror(-r));
		return r;
	}
	struct dirent *e;
	while ((e = readdir(d)) != NULL) {
		uint32_t pid;
		if (!teach_sweep_parse(e->d_name, &pid) || pid == own_pid)
			continue;
		sweep_one(dfd, dir, e->d_name, pid, uid, log, user, n);
	}
	closedir(d);
	close(dfd);
	return 0;
}
