/* teach_rec - teach's recording handed to a new version (docs/DECISIONS.md D57).
 *
 * The recording (up to TEACH_REC_MAX waypoints of 6 joints, 960 KB) does not fit a state block
 * (64 KiB at most). The old half keeps it in a journal file in its data folder
 * (teach-rec-<pid>-<nonce>.bin, mode 0600, written by its non-RT writer thread) and publishes in
 * its state block (arflex.TeachState) the count, a keyed checksum chain over the waypoints
 * (SipHash-2-4, a key drawn at random) and its newest TEACH_REC_TAIL waypoints. The new half
 * reads the journal on its mailbox thread when the ADOPT arrives (teach_rec_load) and at its
 * START joins it with the state block's tail (teach_rec_join, O(tail), no I/O): it takes the
 * recording only whole, every waypoint checked against the chain; anything else is refused
 * with the reason, and the START is refused (the change set hands back to the old half).
 *
 * Chain: h(0) = SipHash(key, nonce); h(i+1) = SipHash(key, h(i) || waypoint i (6 f64, LE)).
 * Pure functions; the file functions do I/O and belong on a non-RT thread.
 */
#ifndef TEACH_REC_H
#define TEACH_REC_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define TEACH_REC_MAX 20000u
#define TEACH_REC_TAIL 128u
#define TEACH_REC_MAGIC "ARFTREC1"
#define TEACH_REC_HEADER 64u /* magic 8, nonce 8, pid 4, count 4, reserved to 64 */

uint64_t teach_rec_siphash(const uint64_t key[2], const void *data, size_t len);
uint64_t teach_rec_seed(const uint64_t key[2], uint64_t nonce);
uint64_t teach_rec_next(const uint64_t key[2], uint64_t h, const double q[6]);

/** What the state block says of the recording (the fields of arflex.TeachState). */
struct teach_rec_claim {
	uint64_t key[2];
	uint64_t nonce;
	uint32_t pid;
	uint32_t count;      /* rec_count */
	uint64_t hash;       /* the chain over count waypoints */
	uint32_t tail_first; /* tail_first + tail_count == count */
	uint32_t tail_count;
	uint64_t tail_hash; /* the chain over tail_first waypoints */
	const double *tail; /* tail_count x 6 */
};

/** The journal read into memory: points[0..count) and chain[0..count] (chain[i] over i
 *  waypoints). Buffers of TEACH_REC_MAX (+1) entries owned by the caller. */
struct teach_rec_loaded {
	double (*points)[6];
	uint64_t *chain;
	uint32_t count;
};

/** The journal's file name for @pid/@nonce into @buf ("teach-rec-<pid>-<nonce hex>.bin"). */
int teach_rec_name(char *buf, size_t size, uint32_t pid, uint64_t nonce);

/** Checks the claim alone (counts, tail in range, the tail's chain ends on hash). 0, or
 *  -EINVAL / -EBADMSG with @why filled. */
int teach_rec_check_claim(const struct teach_rec_claim *c, char *why, size_t why_size);

/**
 * Reads the journal @path (opened without following a link) into @out and computes its chain
 * with the claim's key and nonce. Refused (-errno, @why naming what is wrong): not a regular
 * file, not the caller's own, readable or writable by group or others, more than one link, a
 * size that is not header + count waypoints, another magic, pid or nonce, more than
 * TEACH_REC_MAX, a short read. Does not judge the content against the claim: teach_rec_join
 * does. Blocking I/O: not on the RT thread.
 */
int teach_rec_load(const char *path, const struct teach_rec_claim *c, struct teach_rec_loaded *out,
		   char *why, size_t why_size);

/**
 * Joins a loaded journal and the claim's tail, RT safe (no I/O, no allocation, O(tail)): the
 * journal must hold at least tail_first waypoints whose chain equals tail_hash, and the tail
 * chained on from there must end on hash. On success the tail is copied into
 * @l->points[tail_first..count), @l->count = count and @l->chain extended. 0, -ENODATA (the
 * journal is too short: it does not reach the tail), -EBADMSG (a checksum does not match: a
 * damaged, forged or foreign journal), -EINVAL (the claim is malformed); @why says which, when
 * not NULL (snprintf into a caller's buffer, no allocation).
 */
int teach_rec_join(struct teach_rec_loaded *l, const struct teach_rec_claim *c, char *why,
		   size_t why_size);

/** Writes the header of a journal (count @count) into @hdr (TEACH_REC_HEADER bytes). */
void teach_rec_header(unsigned char hdr[TEACH_REC_HEADER], uint32_t pid, uint64_t nonce,
		      uint32_t count);

#ifdef __cplusplus
}
#endif

#endif
