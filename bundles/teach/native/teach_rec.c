/* teach_rec - see teach_rec.h (docs/DECISIONS.md D57). */
#ifndef _GNU_SOURCE
#define _GNU_SOURCE
#endif
#include "teach_rec.h"

#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

/* ---- SipHash-2-4 (Aumasson, Bernstein), written from the paper's description ---------- */

static uint64_t rotl(uint64_t x, int b)
{
	return (x << b) | (x >> (64 - b));
}

static uint64_t load64(const unsigned char *p)
{
	uint64_t v = 0;
	for (int i = 7; i >= 0; --i)
		v = (v << 8) | p[i];
	return v;
}

#define SIPROUND()                                                                         \
	do {                                                                               \
		v0 += v1;                                                                  \
		v1 = rotl(v1, 13);                                                         \
		v1 ^= v0;                                                                  \
		v0 = rotl(v0, 32);                                                         \
		v2 += v3;                                                                  \
		v3 = rotl(v3, 16);                                                         \
		v3 ^= v2;                                                                  \
		v0 += v3;                                                                  \
		v3 = rotl(v3, 21);                                                         \
		v3 ^= v0;                                                                  \
		v2 += v1;                                                                  \
		v1 = rotl(v1, 17);                                                         \
		v1 ^= v2;                                                                  \
		v2 = rotl(v2, 32);                                                         \
	} while (0)

uint64_t teach_rec_siphash(const uint64_t key[2], const void *data, size_t len)
{
	const unsigned char *in = data;
	uint64_t v0 = 0x736f6d6570736575ULL ^ key[0];
	uint64_t v1 = 0x646f72616e646f6dULL ^ key[1];
	uint64_t v2 = 0x6c7967656e657261ULL ^ key[0];
	uint64_t v3 = 0x7465646279746573ULL ^ key[1];
	size_t full = len - len % 8;
	for (size_t i = 0; i < full; i += 8) {
		uint64_t m = load64(in + i);
		v3 ^= m;
		SIPROUND();
		SIPROUND();
		v0 ^= m;
	}
	uint64_t b = ((uint64_t)len) << 56;
	for (size_t i = 0; i < len % 8; ++i)
		b |= ((uint64_t)in[full + i]) << (8 * i);
	v3 ^= b;
	SIPROUND();
	SIPROUND();
	v0 ^= b;
	v2 ^= 0xff;
	SIPROUND();
	SIPROUND();
	SIPROUND();
	SIPROUND();
	return v0 ^ v1 ^ v2 ^ v3;
}

uint64_t teach_rec_seed(const uint64_t key[2], uint64_t nonce)
{
	return teach_rec_siphash(key, &nonce, sizeof(nonce));
}

uint64_t teach_rec_next(const uint64_t key[2], uint64_t h, const double q[6])
{
	unsigned char buf[8 + 48];
	memcpy(buf, &h, 8);
	memcpy(buf + 8, q, 48);
	return teach_rec_siphash(key, buf, sizeof(buf));
}

/* ---- the claim, the journal, the join ----------------------------------------------------- */

#define WHY(...)                                                                           \
	do {                                                                               \
		if (why && why_size)                                                       \
			snprintf(why, why_size, __VA_ARGS__);                              \
	} while (0)

int teach_rec_name(char *buf, size_t size, uint32_t pid, uint64_t nonce)
{
	int n = snprintf(buf, size, "teach-rec-%" PRIu32 "-%016" PRIx64 ".bin", pid, nonce);
	return n < 0 || (size_t)n >= size ? -ENAMETOOLONG : 0;
}

int teach_rec_check_claim(const struct teach_rec_claim *c, char *why, size_t why_size)
{
	if (c->count > TEACH_REC_MAX) {
		WHY("the state block claims %" PRIu32 " waypoints, more than %u", c->count,
		    TEACH_REC_MAX);
		return -EINVAL;
	}
	if (c->tail_count > TEACH_REC_TAIL || c->tail_first > c->count ||
	    c->count - c->tail_first != c->tail_count) {
		WHY("the state block's tail (waypoints %" PRIu32 "+%" PRIu32
		    ") does not end on its count %" PRIu32,
		    c->tail_first, c->tail_count, c->count);
		return -EINVAL;
	}
	uint64_t h = c->tail_first == 0 ? teach_rec_seed(c->key, c->nonce) : c->tail_hash;
	if (c->tail_first == 0 && h != c->tail_hash) {
		WHY("the state block's chain does not start from its key and nonce");
		return -EBADMSG;
	}
	for (uint32_t i = 0; i < c->tail_count; ++i)
		h = teach_rec_next(c->key, h, c->tail + 6 * (size_t)i);
	if (h != c->hash) {
		WHY("the state block's newest %" PRIu32 " waypoints do not match its checksum",
		    c->tail_count);
		return -EBADMSG;
	}
	return 0;
}

void teach_rec_header(unsigned char hdr[TEACH_REC_HEADER], uint32_t pid, uint64_t nonce,
		      uint32_t count)
{
	memset(hdr, 0, TEACH_REC_HEADER);
	memcpy(hdr, TEACH_REC_MAGIC, 8);
	memcpy(hdr + 8, &nonce, 8);
	memcpy(hdr + 16, &pid, 4);
	memcpy(hdr + 20, &count, 4);
}

static int read_all(int fd, void *buf, size_t len, off_t off)
{
	unsigned char *p = buf;
	while (len) {
		ssize_t n = pread(fd, p, len, off);
		if (n < 0 && errno == EINTR)
			continue;
		if (n <= 0)
			return n < 0 ? -errno : -EIO;
		p += n;
		len -= (size_t)n;
		off += n;
	}
	return 0;
}

int teach_rec_load(const char *path, const struct teach_rec_claim *c, struct teach_rec_loaded *out,
		   char *why, size_t why_size)
{
	struct stat st;
	unsigned char hdr[TEACH_REC_HEADER];
	uint32_t pid, count;
	uint64_t nonce;
	int r;

	out->count = 0;
	int fd = open(path, O_RDONLY | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK);
	if (fd < 0) {
		r = -errno;
		WHY("the recording's journal %s: %s", path, strerror(-r));
		return r;
	}
	if (fstat(fd, &st) != 0) {
		r = -errno;
		WHY("the recording's journal %s: %s", path, strerror(-r));
		goto out;
	}
	r = -EPERM;
	if (!S_ISREG(st.st_mode)) {
		WHY("the recording's journal %s is not a regular file", path);
		goto out;
	}
	if (st.st_uid != geteuid()) {
		WHY("the recording's journal %s belongs to uid %u, not to this process (uid %u)", path,
		    (unsigned)st.st_uid, (unsigned)geteuid());
		goto out;
	}
	if (st.st_mode & 077) {
		WHY("the recording's journal %s is open to group or others (mode %03o)", path,
		    (unsigned)(st.st_mode & 0777));
		goto out;
	}
	if (st.st_nlink != 1) {
		WHY("the recording's journal %s has %lu links", path, (unsigned long)st.st_nlink);
		goto out;
	}
	r = -EBADMSG;
	if (st.st_size < (off_t)TEACH_REC_HEADER) {
		WHY("the recording's journal %s is truncated (%lld bytes, no header)", path,
		    (long long)st.st_size);
		goto out;
	}
	if ((r = read_all(fd, hdr, sizeof(hdr), 0)) != 0) {
		WHY("the recording's journal %s: reading its header: %s", path, strerror(-r));
		goto out;
	}
	memcpy(&nonce, hdr + 8, 8);
	memcpy(&pid, hdr + 16, 4);
	memcpy(&count, hdr + 20, 4);
	r = -EBADMSG;
	if (memcmp(hdr, TEACH_REC_MAGIC, 8) != 0) {
		WHY("the recording's journal %s is not a teach journal (magic)", path);
		goto out;
	}
	if (nonce != c->nonce || pid != c->pid) {
		WHY("the recording's journal %s names another recording (pid %" PRIu32
		    ", nonce %016" PRIx64 ")",
		    path, pid, nonce);
		goto out;
	}
	if (count > TEACH_REC_MAX) {
		WHY("the recording's journal %s claims %" PRIu32 " waypoints, more than %u", path,
		    count, TEACH_REC_MAX);
		goto out;
	}
	if (st.st_size != (off_t)TEACH_REC_HEADER + (off_t)count * 48) {
		WHY("the recording's journal %s is %lld bytes, its header says %" PRIu32
		    " waypoints (%lld bytes): truncated or padded",
		    path, (long long)st.st_size, count,
		    (long long)TEACH_REC_HEADER + (long long)count * 48);
		goto out;
	}
	if (count && (r = read_all(fd, out->points, (size_t)count * 48, TEACH_REC_HEADER)) != 0) {
		WHY("the recording's journal %s: reading %" PRIu32 " waypoints: %s", path, count,
		    strerror(-r));
		goto out;
	}
	out->chain[0] = teach_rec_seed(c->key, c->nonce);
	for (uint32_t i = 0; i < count; ++i)
		out->chain[i + 1] = teach_rec_next(c->key, out->chain[i], out->points[i]);
	out->count = count;
	r = 0;
out:
	close(fd);
	return r;
}

int teach_rec_join(struct teach_rec_loaded *l, const struct teach_rec_claim *c, char *why,
		   size_t why_size)
{
	int r = teach_rec_check_claim(c, why, why_size);
	if (r)
		return r;
	if (c->tail_first > 0) {
		if (l->count < c->tail_first) {
			WHY("the recording's journal holds %" PRIu32
			    " waypoints; the state block's newest begin at %" PRIu32
			    " (of %" PRIu32 "): %" PRIu32 " are missing",
			    l->count, c->tail_first, c->count, c->tail_first - l->count);
			return -ENODATA;
		}
		if (l->chain[c->tail_first] != c->tail_hash) {
			WHY("the recording's journal does not match the state block's checksum over its first %" PRIu32
			    " waypoints (damaged, forged or of another recording)",
			    c->tail_first);
			return -EBADMSG;
		}
	} else {
		l->chain[0] = c->tail_hash; /* == the seed: checked with the claim */
	}
	for (uint32_t i = 0; i < c->tail_count; ++i) {
		uint32_t k = c->tail_first + i;
		memcpy(l->points[k], c->tail + 6 * (size_t)i, 48);
		l->chain[k + 1] = teach_rec_next(c->key, l->chain[k], l->points[k]);
	}
	l->count = c->count;
	return 0;
}
