/* The test kit without a test framework: ids, leak checks, small file reads. Linked by the
 * cmocka suites (through arflex_test_helper) and by the component tests of the bundles. */
#define _GNU_SOURCE
#include "helper.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <mqueue.h>
#include <stdio.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>


void th_rid(char *buf, size_t size, const char *tag)
{
	snprintf(buf, size, "t%s-%ld", tag, (long)getpid());
}

static int scan(const char *dir, const char *prefix, bool remove, bool is_mq)
{
	DIR *d = opendir(dir);
	struct dirent *e;
	int n = 0;

	if (!d)
		return 0;
	while ((e = readdir(d))) {
		if (strncmp(e->d_name, prefix, strlen(prefix)))
			continue;
		n++;
		if (remove) {
			char name[300];

			snprintf(name, sizeof(name), "/%s", e->d_name);
			if (is_mq)
				mq_unlink(name);
			else
				shm_unlink(name);
		} else {
			fprintf(stderr, "leftover: %s/%s\n", dir, e->d_name);
		}
	}
	closedir(d);
	return n;
}

static char tracked[32][96];
static int ntracked;

void th_track(const char *rid, const char *inst)
{
	char base[96];

	snprintf(base, sizeof(base), "/arflex.%s.%s.", rid, inst);
	for (int i = 0; i < ntracked; i++)
		if (!strcmp(tracked[i], base))
			return;
	if (ntracked < 32)
		strcpy(tracked[ntracked++], base);
}

static int probe_tracked(const char *rid, bool remove)
{
	char prefix[80], name[200];
	int n = 0;

	snprintf(prefix, sizeof(prefix), "/arflex.%s.", rid);
	for (int i = 0; i < ntracked; i++) {
		if (strncmp(tracked[i], prefix, strlen(prefix)))
			continue;
		for (int k = 0; k < 2; k++) {
			mqd_t q;

			snprintf(name, sizeof(name), "%.100s%s", tracked[i], k ? "rsp" : "cmd");
			q = mq_open(name, O_RDONLY);
			if (q == (mqd_t)-1)
				continue;
			mq_close(q);
			n++;
			if (remove)
				mq_unlink(name);
			else
				fprintf(stderr, "leftover queue: %s\n", name);
		}
	}
	return n;
}

int th_leftovers(const char *rid)
{
	char prefix[80];
	int n;

	snprintf(prefix, sizeof(prefix), "arflex.%s.", rid);
	n = scan("/dev/shm", prefix, false, false);
	if (access("/dev/mqueue", F_OK) == 0)
		n += scan("/dev/mqueue", prefix, false, true);
	else
		n += probe_tracked(rid, false);
	return n;
}

void th_sweep(const char *rid)
{
	char prefix[80];

	snprintf(prefix, sizeof(prefix), "arflex.%s.", rid);
	scan("/dev/shm", prefix, true, false);
	scan("/dev/mqueue", prefix, true, true);
	probe_tracked(rid, true);
}

bool th_no_children(void)
{
	int st;

	return waitpid(-1, &st, WNOHANG) < 0 && errno == ECHILD;
}

static int count_threads(void)
{
	DIR *d = opendir("/proc/self/task");
	struct dirent *e;
	int n = 0;

	if (!d)
		return -1;
	while ((e = readdir(d)))
		if (e->d_name[0] != '.')
			n++;
	closedir(d);
	return n;
}

int th_threads(void)
{
	/* pthread_join returns when the kernel clears the thread's tid, a moment before the
	 * thread leaves /proc/self/task: a joined thread may still be listed. Wait (1 s at
	 * most) for the count to settle at one before reporting more. */
	struct timespec step = { 0, 1000000 };
	int n = count_threads();

	for (int i = 0; i < 1000 && n > 1; i++) {
		nanosleep(&step, NULL);
		n = count_threads();
	}
	return n;
}


long th_read_file(const char *path, char *buf, size_t size)
{
	FILE *f = fopen(path, "r");
	size_t n;

	if (!f)
		return -1;
	n = fread(buf, 1, size - 1, f);
	buf[n] = 0;
	fclose(f);
	return (long)n;
}
