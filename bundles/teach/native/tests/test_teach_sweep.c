/* teach.sweep: the journals of teach halves that are gone are removed, nothing else is
 * (teach_sweep.h, docs/DECISIONS.md D63): not the sweeper's own, not one whose writer runs
 * (its pid exists, or its lock is held), not a symlink, FIFO, folder, hard link or another
 * owner's file named like a journal (each refused with a line naming it), not a folder open to
 * others. Real processes: a dead writer is a child that exited and was reaped. */
#include <errno.h>
#include <fcntl.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#include "teach_sweep.h"

static char dir[96], outside[96];
static char lines[32][512];
static int nlines;

static void log_line(void *user, const char *line)
{
	(void)user;
	if (nlines < 32)
		snprintf(lines[nlines++], sizeof(lines[0]), "%s", line);
	printf("  log: %s\n", line);
}

/* The line naming @name and containing @what, or NULL. */
static const char *logged(const char *name, const char *what)
{
	for (int i = 0; i < nlines; ++i)
		if (strstr(lines[i], name) && strstr(lines[i], what))
			return lines[i];
	return NULL;
}

static void path_of(char *buf, size_t n, const char *name)
{
	snprintf(buf, n, "%s/%s", dir, name);
}

static void jname(char *buf, size_t n, pid_t pid, uint64_t nonce)
{
	snprintf(buf, n, "teach-rec-%d-%016llx.bin", (int)pid, (unsigned long long)nonce);
}

static void make_file(const char *name, mode_t mode)
{
	char p[200];
	path_of(p, sizeof(p), name);
	int fd = open(p, O_WRONLY | O_CREAT | O_EXCL, mode);
	assert_true(fd >= 0);
	assert_int_equal(write(fd, "ARFTREC1", 8), 8);
	assert_int_equal(fchmod(fd, mode), 0);
	close(fd);
}

static int exists(const char *name)
{
	char p[200];
	struct stat st;
	path_of(p, sizeof(p), name);
	return lstat(p, &st) == 0;
}

/* A pid that was a process and is no more (a child that exited, reaped). */
static pid_t dead_pid(void)
{
	pid_t p = fork();
	assert_true(p >= 0);
	if (p == 0)
		_exit(0);
	int st;
	assert_int_equal(waitpid(p, &st, 0), p);
	assert_int_equal(kill(p, 0), -1);
	return p;
}

/* A running child that holds (lock != NULL: flock on that file of dir) until told to go. */
struct live {
	pid_t pid;
	int go[2];
};

static void live_start(struct live *l, const char *lock)
{
	int ready[2];
	assert_int_equal(pipe(l->go), 0);
	assert_int_equal(pipe(ready), 0);
	l->pid = fork();
	assert_true(l->pid >= 0);
	if (l->pid == 0) {
		char c = 1, p[200];
		close(l->go[1]);
		if (lock) {
			path_of(p, sizeof(p), lock);
			int fd = open(p, O_RDONLY);
			if (fd < 0 || flock(fd, LOCK_EX) != 0)
				c = 0;
		}
		if (write(ready[1], &c, 1) != 1)
			_exit(2);
		if (read(l->go[0], &c, 1) < 0)
			_exit(2);
		_exit(0);
	}
	close(l->go[0]);
	close(ready[1]);
	char c = 0;
	assert_int_equal(read(ready[0], &c, 1), 1);
	assert_int_equal(c, 1);
	close(ready[0]);
}

static void live_stop(struct live *l)
{
	int st;
	close(l->go[1]);
	assert_int_equal(waitpid(l->pid, &st, 0), l->pid);
}

static int setup(void **state)
{
	(void)state;
	nlines = 0;
	snprintf(dir, sizeof(dir), "/tmp/teach-sweep-test.%d", (int)getpid());
	snprintf(outside, sizeof(outside), "/tmp/teach-sweep-victim.%d", (int)getpid());
	assert_int_equal(mkdir(dir, 0700), 0);
	return 0;
}

static int teardown(void **state)
{
	(void)state;
	char cmd[256];
	snprintf(cmd, sizeof(cmd), "rm -rf '%s' '%s'", dir, outside);
	if (system(cmd) != 0)
		return -1;
	return 0;
}

static void journal_names_are_parsed_strictly(void **state)
{
	(void)state;
	uint32_t pid = 0;
	assert_true(teach_sweep_parse("teach-rec-4242-0123456789abcdef.bin", &pid));
	assert_int_equal(pid, 4242);
	assert_false(teach_sweep_parse("teach-rec-4242-0123456789abcde.bin", &pid));   /* 15 hex */
	assert_false(teach_sweep_parse("teach-rec-4242-0123456789abcdefa.bin", &pid)); /* 17 hex */
	assert_false(teach_sweep_parse("teach-rec-4242-0123456789ABCDEF.bin", &pid));  /* upper case */
	assert_false(teach_sweep_parse("teach-rec-0-0123456789abcdef.bin", &pid));     /* no process */
	assert_false(teach_sweep_parse("teach-rec-2147483648-0123456789abcdef.bin", &pid));
	assert_false(teach_sweep_parse("teach-rec--1-0123456789abcdef.bin", &pid));
	assert_false(teach_sweep_parse("teach-rec-4242-0123456789abcdef.bin.tmp", &pid));
	assert_false(teach_sweep_parse("program-1.arp", &pid));
}

/* The case of the issue: a killed half's journal goes; the sweeper's own, a running half's and
 * a journal whose writer's lock is held stay; other files are not looked at. */
static void the_journal_of_a_dead_half_is_removed_and_nothing_a_running_half_uses(void **state)
{
	(void)state;
	char own[64], dead[64], running[64], locked[64];
	jname(own, sizeof(own), getpid(), 1);
	jname(dead, sizeof(dead), dead_pid(), 2);
	pid_t gone = dead_pid(); /* a pid that names no process, its file locked by a live one */
	jname(locked, sizeof(locked), gone, 3);
	make_file(own, 0600);
	make_file(dead, 0600);
	make_file(locked, 0600);
	make_file("program-1.arp", 0600);
	make_file("teach-rec-1-xyz.bin", 0600);
	struct live run, holder;
	live_start(&run, NULL);
	jname(running, sizeof(running), run.pid, 4);
	make_file(running, 0600);
	live_start(&holder, locked);

	struct teach_sweep_count n;
	assert_int_equal(teach_sweep(dir, (uint32_t)getpid(), geteuid(), log_line, NULL, &n), 0);
	assert_false(exists(dead));
	assert_true(exists(own));
	assert_true(exists(running));
	assert_true(exists(locked));
	assert_true(exists("program-1.arp"));
	assert_true(exists("teach-rec-1-xyz.bin"));
	assert_int_equal(n.removed, 1);
	assert_int_equal(n.kept, 2);
	assert_int_equal(n.refused, 0);
	assert_non_null(logged(dead, "removed"));
	assert_non_null(logged(running, "is running"));
	assert_non_null(logged(locked, "lock"));
	assert_null(logged(own, ""));
	assert_null(logged("program-1.arp", ""));

	/* once the holder and the running half are gone, theirs go too */
	live_stop(&holder);
	live_stop(&run);
	assert_int_equal(teach_sweep(dir, (uint32_t)getpid(), geteuid(), log_line, NULL, &n), 0);
	assert_int_equal(n.removed, 2);
	assert_false(exists(locked));
	assert_false(exists(running));
	assert_true(exists(own));
}

/* A symlink named like a dead half's journal: neither followed nor removed, nor its target;
 * a FIFO (an open would block), a folder and a second hard link are refused the same way. */
static void a_symlink_fifo_folder_or_hard_link_named_like_a_journal_is_refused(void **state)
{
	(void)state;
	char lnk[64], fifo[64], folder[64], hard[64], p[200], q[200];
	pid_t gone = dead_pid();
	jname(lnk, sizeof(lnk), gone, 5);
	jname(fifo, sizeof(fifo), gone, 6);
	jname(folder, sizeof(folder), gone, 7);
	jname(hard, sizeof(hard), gone, 8);
	int fd = open(outside, O_WRONLY | O_CREAT | O_EXCL, 0600);
	assert_true(fd >= 0);
	assert_int_equal(write(fd, "precious", 8), 8);
	close(fd);
	path_of(p, sizeof(p), lnk);
	assert_int_equal(symlink(outside, p), 0);
	path_of(p, sizeof(p), fifo);
	assert_int_equal(mkfifo(p, 0600), 0);
	path_of(p, sizeof(p), folder);
	assert_int_equal(mkdir(p, 0700), 0);
	make_file("keep.arp", 0600);
	path_of(p, sizeof(p), "keep.arp");
	path_of(q, sizeof(q), hard);
	assert_int_equal(link(p, q), 0);

	struct teach_sweep_count n;
	assert_int_equal(teach_sweep(dir, (uint32_t)getpid(), geteuid(), log_line, NULL, &n), 0);
	assert_int_equal(n.removed, 0);
	assert_int_equal(n.refused, 4);
	assert_true(exists(lnk));
	assert_true(exists(fifo));
	assert_true(exists(folder));
	assert_true(exists(hard));
	struct stat st;
	assert_int_equal(stat(outside, &st), 0);
	assert_int_equal(st.st_size, 8);
	assert_non_null(logged(lnk, "symbolic link"));
	assert_non_null(logged(fifo, "not a regular file"));
	assert_non_null(logged(folder, "not a regular file"));
	assert_non_null(logged(hard, "2 links"));
}

/* A regular file of another uid named like a dead half's journal stays (logged with its uid).
 * As root the file is given to uid 12345; otherwise the sweep runs as another uid. */
static void another_owners_file_named_like_a_journal_is_refused(void **state)
{
	(void)state;
	char foreign[64], p[200];
	jname(foreign, sizeof(foreign), dead_pid(), 9);
	make_file(foreign, 0600);
	uid_t as = geteuid();
	path_of(p, sizeof(p), foreign);
	if (geteuid() == 0)
		assert_int_equal(lchown(p, 12345, 12345), 0);
	else
		as = geteuid() + 1;
	struct teach_sweep_count n;
	/* the folder is the sweeper's: as another uid it is refused whole, see below */
	if (as == geteuid()) {
		assert_int_equal(teach_sweep(dir, (uint32_t)getpid(), as, log_line, NULL, &n), 0);
		assert_int_equal(n.refused, 1);
		assert_int_equal(n.removed, 0);
		assert_true(exists(foreign));
		assert_non_null(logged(foreign, "belongs to uid 12345"));
	} else {
		assert_int_equal(teach_sweep(dir, (uint32_t)getpid(), as, log_line, NULL, &n), -EPERM);
		assert_true(exists(foreign));
	}
}

/* A folder open to others, or a link to a folder, is not swept at all. */
static void a_folder_writable_by_others_or_a_link_is_not_swept(void **state)
{
	(void)state;
	char dead[64], p[200];
	jname(dead, sizeof(dead), dead_pid(), 10);
	make_file(dead, 0600);
	assert_int_equal(chmod(dir, 0777), 0);
	struct teach_sweep_count n;
	assert_int_equal(teach_sweep(dir, (uint32_t)getpid(), geteuid(), log_line, NULL, &n), -EPERM);
	assert_true(exists(dead));
	assert_non_null(logged(dir, "writable by group or others"));
	assert_int_equal(chmod(dir, 0700), 0);
	snprintf(p, sizeof(p), "%s.link", dir);
	unlink(p);
	assert_int_equal(symlink(dir, p), 0);
	assert_int_equal(teach_sweep(p, (uint32_t)getpid(), geteuid(), log_line, NULL, &n), -ELOOP);
	unlink(p);
	assert_true(exists(dead));
	/* a folder that does not exist: nothing to do */
	snprintf(p, sizeof(p), "%s/none", dir);
	assert_int_equal(teach_sweep(p, (uint32_t)getpid(), geteuid(), log_line, NULL, &n), 0);
	assert_int_equal(n.removed + n.kept + n.refused, 0);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(journal_names_are_parsed_strictly),
		cmocka_unit_test_setup_teardown(the_journal_of_a_dead_half_is_removed_and_nothing_a_running_half_uses,
						setup, teardown),
		cmocka_unit_test_setup_teardown(a_symlink_fifo_folder_or_hard_link_named_like_a_journal_is_refused,
						setup, teardown),
		cmocka_unit_test_setup_teardown(another_owners_file_named_like_a_journal_is_refused, setup, teardown),
		cmocka_unit_test_setup_teardown(a_folder_writable_by_others_or_a_link_is_not_swept, setup, teardown),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
