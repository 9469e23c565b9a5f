/* teach.rec: the checks a new teach half makes before it takes a recording over (teach_rec.h,
 * docs/DECISIONS.md D57): only a whole recording, every waypoint against the state block's
 * keyed chain; a short, forged, foreign, open or linked journal is refused with its reason. */
#include <errno.h>
#include <fcntl.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmocka.h>

#include "teach_rec.h"

static const uint64_t KEY[2] = {0x0706050403020100ULL, 0x0f0e0d0c0b0a0908ULL};
static const uint64_t NONCE = 0x1234abcd5678ef00ULL;
static const uint32_t PID = 4242;

/* The old half's side: a recording of n waypoints, its chain, its claim. */
struct old_half {
	double (*pts)[6];
	uint64_t *chain;
	uint32_t n;
	double tail[TEACH_REC_TAIL * 6];
	struct teach_rec_claim claim;
};

static void record(struct old_half *o, uint32_t n, double salt)
{
	o->n = n;
	o->chain[0] = teach_rec_seed(KEY, NONCE);
	for (uint32_t i = 0; i < n; ++i) {
		for (int j = 0; j < 6; ++j)
			o->pts[i][j] = salt + 0.001 * i + 0.1 * j;
		o->chain[i + 1] = teach_rec_next(KEY, o->chain[i], o->pts[i]);
	}
	uint32_t t = n < TEACH_REC_TAIL ? n : TEACH_REC_TAIL;
	memset(&o->claim, 0, sizeof(o->claim));
	o->claim.key[0] = KEY[0];
	o->claim.key[1] = KEY[1];
	o->claim.nonce = NONCE;
	o->claim.pid = PID;
	o->claim.count = n;
	o->claim.hash = o->chain[n];
	o->claim.tail_first = n - t;
	o->claim.tail_count = t;
	o->claim.tail_hash = o->chain[n - t];
	memcpy(o->tail, o->pts[n - t], (size_t)t * 48);
	o->claim.tail = o->tail;
}

static char dir[64];

static void journal(const char *path, const struct old_half *o, uint32_t n, mode_t mode)
{
	unsigned char hdr[TEACH_REC_HEADER];
	unlink(path);
	int fd = open(path, O_WRONLY | O_CREAT | O_EXCL, 0600);
	assert_true(fd >= 0);
	teach_rec_header(hdr, PID, NONCE, n);
	assert_int_equal(write(fd, hdr, sizeof(hdr)), (ssize_t)sizeof(hdr));
	assert_int_equal(write(fd, o->pts, (size_t)n * 48), (ssize_t)n * 48);
	assert_int_equal(fchmod(fd, mode), 0);
	close(fd);
}

struct fixture {
	struct old_half o;
	struct teach_rec_loaded l;
	char path[160];
	char why[512];
};

static int setup(void **state)
{
	struct fixture *f = calloc(1, sizeof(*f));
	f->o.pts = calloc(TEACH_REC_MAX, 48);
	f->o.chain = calloc(TEACH_REC_MAX + 1, 8);
	f->l.points = calloc(TEACH_REC_MAX, 48);
	f->l.chain = calloc(TEACH_REC_MAX + 1, 8);
	snprintf(dir, sizeof(dir), "/tmp/teach-rec-test.%d", (int)getpid());
	mkdir(dir, 0700);
	snprintf(f->path, sizeof(f->path), "%s/j.bin", dir);
	*state = f;
	return 0;
}

static int teardown(void **state)
{
	struct fixture *f = *state;
	unlink(f->path);
	char lk[200];
	snprintf(lk, sizeof(lk), "%s/link.bin", dir);
	unlink(lk);
	rmdir(dir);
	free(f->o.pts);
	free(f->o.chain);
	free(f->l.points);
	free(f->l.chain);
	free(f);
	return 0;
}

/* The published test vector of SipHash-2-4: key 00..0f, message 00..0e. */
static void siphash_matches_the_reference_vector(void **state)
{
	(void)state;
	unsigned char m[15];
	for (int i = 0; i < 15; ++i)
		m[i] = (unsigned char)i;
	assert_int_equal(teach_rec_siphash(KEY, m, sizeof(m)), 0xa129ca6149be45e5ULL);
}

static void a_whole_recording_is_taken(void **state)
{
	struct fixture *f = *state;
	record(&f->o, 20000, 0.5);
	journal(f->path, &f->o, 20000 - 10, 0600); /* the journal lags the tail by 10 */
	assert_int_equal(teach_rec_load(f->path, &f->o.claim, &f->l, f->why, sizeof(f->why)), 0);
	assert_int_equal(f->l.count, 19990);
	assert_int_equal(teach_rec_join(&f->l, &f->o.claim, f->why, sizeof(f->why)), 0);
	assert_int_equal(f->l.count, 20000);
	assert_memory_equal(f->l.points, f->o.pts, 20000 * 48);
	assert_int_equal(f->l.chain[20000], f->o.claim.hash);
}

/* Loaded at the ADOPT, joined again at the START after the old half recorded more. */
static void more_recorded_between_adopt_and_start_is_joined_from_the_tail(void **state)
{
	struct fixture *f = *state;
	record(&f->o, 1000, 0.5);
	journal(f->path, &f->o, 1000, 0600);
	assert_int_equal(teach_rec_load(f->path, &f->o.claim, &f->l, f->why, sizeof(f->why)), 0);
	assert_int_equal(teach_rec_join(&f->l, &f->o.claim, f->why, sizeof(f->why)), 0);
	record(&f->o, 1100, 0.5); /* same episode, 100 more */
	assert_int_equal(teach_rec_join(&f->l, &f->o.claim, f->why, sizeof(f->why)), 0);
	assert_int_equal(f->l.count, 1100);
	assert_memory_equal(f->l.points, f->o.pts, 1100 * 48);
}

static void a_journal_that_does_not_reach_the_tail_is_refused(void **state)
{
	struct fixture *f = *state;
	record(&f->o, 1000, 0.5);
	journal(f->path, &f->o, 800, 0600); /* the tail begins at 872 */
	assert_int_equal(teach_rec_load(f->path, &f->o.claim, &f->l, f->why, sizeof(f->why)), 0);
	assert_int_equal(teach_rec_join(&f->l, &f->o.claim, f->why, sizeof(f->why)), -ENODATA);
	assert_non_null(strstr(f->why, "holds 800 waypoints"));
	assert_non_null(strstr(f->why, "72 are missing"));
}

static void a_forged_waypoint_is_refused(void **state)
{
	struct fixture *f = *state;
	record(&f->o, 1000, 0.5);
	f->o.pts[17][3] += 1e-9; /* one waypoint changed in the file, its size right */
	journal(f->path, &f->o, 1000, 0600);
	assert_int_equal(teach_rec_load(f->path, &f->o.claim, &f->l, f->why, sizeof(f->why)), 0);
	assert_int_equal(teach_rec_join(&f->l, &f->o.claim, f->why, sizeof(f->why)), -EBADMSG);
	assert_non_null(strstr(f->why, "does not match the state block's checksum over its first 872"));
}

static void a_truncated_journal_is_refused(void **state)
{
	struct fixture *f = *state;
	record(&f->o, 1000, 0.5);
	journal(f->path, &f->o, 1000, 0600);
	assert_int_equal(truncate(f->path, TEACH_REC_HEADER + 500 * 48 + 7), 0);
	assert_int_equal(teach_rec_load(f->path, &f->o.claim, &f->l, f->why, sizeof(f->why)), -EBADMSG);
	assert_non_null(strstr(f->why, "truncated or padded"));
	assert_int_equal(f->l.count, 0);
	assert_int_equal(truncate(f->path, 10), 0);
	assert_int_equal(teach_rec_load(f->path, &f->o.claim, &f->l, f->why, sizeof(f->why)), -EBADMSG);
	assert_non_null(strstr(f->why, "no header"));
}

static void a_journal_of_another_recording_is_refused(void **state)
{
	struct fixture *f = *state;
	record(&f->o, 1000, 0.5);
	journal(f->path, &f->o, 1000, 0600);
	f->o.claim.nonce ^= 1;
	assert_int_equal(teach_rec_load(f->path, &f->o.claim, &f->l, f->why, sizeof(f->why)), -EBADMSG);
	assert_non_null(strstr(f->why, "names another recording"));
	/* the same file under a claim whose episode started over (other waypoints, same nonce) */
	record(&f->o, 1000, 0.5);
	journal(f->path, &f->o, 1000, 0600);
	record(&f->o, 900, 0.7);
	assert_int_equal(teach_rec_load(f->path, &f->o.claim, &f->l, f->why, sizeof(f->why)), 0);
	assert_int_equal(teach_rec_join(&f->l, &f->o.claim, f->why, sizeof(f->why)), -EBADMSG);
}

static void an_open_or_linked_journal_is_refused(void **state)
{
	struct fixture *f = *state;
	record(&f->o, 1000, 0.5);
	journal(f->path, &f->o, 1000, 0644);
	assert_int_equal(teach_rec_load(f->path, &f->o.claim, &f->l, f->why, sizeof(f->why)), -EPERM);
	assert_non_null(strstr(f->why, "open to group or others (mode 644)"));
	assert_int_equal(chmod(f->path, 0600), 0);
	char lk[200];
	snprintf(lk, sizeof(lk), "%s/link.bin", dir);
	assert_int_equal(symlink(f->path, lk), 0);
	assert_int_equal(teach_rec_load(lk, &f->o.claim, &f->l, f->why, sizeof(f->why)), -ELOOP);
	unlink(lk);
	assert_int_equal(link(f->path, lk), 0); /* a second name: someone else may write it */
	assert_int_equal(teach_rec_load(f->path, &f->o.claim, &f->l, f->why, sizeof(f->why)), -EPERM);
	assert_non_null(strstr(f->why, "2 links"));
	unlink(lk);
	assert_int_equal(teach_rec_load(f->path, &f->o.claim, &f->l, f->why, sizeof(f->why)), 0);
}

static void a_malformed_claim_is_refused(void **state)
{
	struct fixture *f = *state;
	record(&f->o, 1000, 0.5);
	struct teach_rec_claim c = f->o.claim;
	c.tail_count = 127;
	assert_int_equal(teach_rec_check_claim(&c, f->why, sizeof(f->why)), -EINVAL);
	assert_non_null(strstr(f->why, "does not end on its count 1000"));
	c = f->o.claim;
	c.count = TEACH_REC_MAX + 1;
	assert_int_equal(teach_rec_check_claim(&c, f->why, sizeof(f->why)), -EINVAL);
	c = f->o.claim;
	f->o.tail[5] += 1.0; /* the tail does not chain on to the hash */
	assert_int_equal(teach_rec_check_claim(&c, f->why, sizeof(f->why)), -EBADMSG);
	assert_non_null(strstr(f->why, "newest 128 waypoints do not match"));
	c.key[0] ^= 1; /* another key */
	f->o.tail[5] -= 1.0;
	assert_int_equal(teach_rec_check_claim(&c, f->why, sizeof(f->why)), -EBADMSG);
}

/* A recording that fits the tail needs no journal. */
static void a_short_recording_is_all_in_the_state_block(void **state)
{
	struct fixture *f = *state;
	record(&f->o, 60, 0.5);
	f->l.count = 0;
	assert_int_equal(teach_rec_join(&f->l, &f->o.claim, f->why, sizeof(f->why)), 0);
	assert_int_equal(f->l.count, 60);
	assert_memory_equal(f->l.points, f->o.pts, 60 * 48);
	record(&f->o, 0, 0.5);
	assert_int_equal(teach_rec_join(&f->l, &f->o.claim, f->why, sizeof(f->why)), 0);
	assert_int_equal(f->l.count, 0);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(siphash_matches_the_reference_vector),
		cmocka_unit_test_setup_teardown(a_whole_recording_is_taken, setup, teardown),
		cmocka_unit_test_setup_teardown(more_recorded_between_adopt_and_start_is_joined_from_the_tail, setup, teardown),
		cmocka_unit_test_setup_teardown(a_journal_that_does_not_reach_the_tail_is_refused, setup, teardown),
		cmocka_unit_test_setup_teardown(a_forged_waypoint_is_refused, setup, teardown),
		cmocka_unit_test_setup_teardown(a_truncated_journal_is_refused, setup, teardown),
		cmocka_unit_test_setup_teardown(a_journal_of_another_recording_is_refused, setup, teardown),
		cmocka_unit_test_setup_teardown(an_open_or_linked_journal_is_refused, setup, teardown),
		cmocka_unit_test_setup_teardown(a_malformed_claim_is_refused, setup, teardown),
		cmocka_unit_test_setup_teardown(a_short_recording_is_all_in_the_state_block, setup, teardown),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
