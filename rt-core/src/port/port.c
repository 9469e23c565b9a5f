/* Port segments: state (seqlock), stream (SPSC ring), frame (ring of large slots). */
#include "arflex/port.h"

#include <errno.h>
#include <fcntl.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#define LOAD(p) __atomic_load_n((p), __ATOMIC_ACQUIRE)
#define LOADR(p) __atomic_load_n((p), __ATOMIC_RELAXED)
#define STORE(p, v) __atomic_store_n((p), (v), __ATOMIC_RELEASE)
#define STORER(p, v) __atomic_store_n((p), (v), __ATOMIC_RELAXED)

bool arflex_port_name_valid(const char *s)
{
	size_t n = 0;

	for (; s && s[n]; n++) {
		char ch = s[n];

		if (n >= ARFLEX_NAME_SIZE - 1)
			return false;
		if (!((ch >= 'a' && ch <= 'z') || (ch >= '0' && ch <= '9') || ch == '_'))
			return false;
	}
	return n > 0;
}

uint64_t arflex_port_type_hash(const char *name)
{
	uint64_t h = UINT64_C(0xcbf29ce484222325);

	for (const unsigned char *p = (const unsigned char *)name; *p; p++) {
		h ^= *p;
		h *= UINT64_C(0x100000001b3);
	}
	return h;
}

/* ABI 2.0 (D30): the payload follows the 24-byte slot header directly; the slot is rounded up
 * to whole cache lines. Computed in 64 bits: elem <= ARFLEX_PORT_MAX_ELEM, so it fits. */
static uint32_t stride_of(uint32_t elem)
{
	uint64_t s = (uint64_t)ARFLEX_SLOT_HDR_SIZE + elem + (ARFLEX_SLOT_ALIGN - 1u);

	return (uint32_t)(s & ~(uint64_t)(ARFLEX_SLOT_ALIGN - 1u));
}

static int spec_valid(const struct arflex_port_spec *s)
{
	if (!s || !s->type.name || !*s->type.name ||
	    strlen(s->type.name) >= ARFLEX_TYPE_NAME_SIZE)
		return 0;
	if (s->type.elem_size == 0 || s->type.elem_size > ARFLEX_PORT_MAX_ELEM)
		return 0;
	switch (s->method) {
	case ARFLEX_PORT_STATE:
		return 1;
	case ARFLEX_PORT_STREAM:
		return s->depth >= 1 && s->depth <= ARFLEX_PORT_MAX_DEPTH &&
		       (s->overflow == ARFLEX_OVERFLOW_DROP_OLDEST ||
			s->overflow == ARFLEX_OVERFLOW_DROP_NEWEST);
	case ARFLEX_PORT_FRAME:
		return s->depth >= 2 && s->depth <= ARFLEX_PORT_MAX_DEPTH;
	default:
		return 0;
	}
}

size_t arflex_port_segment_size(const struct arflex_port_spec *spec)
{
	uint64_t depth, sz;

	if (!spec_valid(spec))
		return 0;
	depth = spec->method == ARFLEX_PORT_STATE ? 1 : spec->depth;
	sz = ARFLEX_PORT_HDR_SIZE + depth * stride_of(spec->type.elem_size);
	return (size_t)((sz + 4095u) & ~(uint64_t)4095u);
}

static void bind_view(struct arflex_port *p)
{
	struct arflex_port_hdr *h = p->base;

	p->hdr = h;
	p->slots = (uint8_t *)p->base + ARFLEX_PORT_HDR_SIZE;
	p->stride = h->slot_stride;
	p->depth = h->depth;
	p->elem_size = h->elem_size;
	p->method = h->method;
	p->overflow = h->overflow;
}

int arflex_port_create(struct arflex_port *p, const char *shm_name,
		       const struct arflex_port_spec *spec)
{
	size_t len = arflex_port_segment_size(spec);
	struct arflex_port_hdr *h;
	void *base;
	int fd, r;

	memset(p, 0, sizeof(*p));
	if (!len || !shm_name || strlen(shm_name) >= sizeof(p->name))
		return -EINVAL;
	fd = arflex_sys_shm_open(shm_name, O_CREAT | O_EXCL | O_RDWR, 0600);
	if (fd < 0)
		return fd;
	r = arflex_sys_ftruncate(fd, (off_t)len);
	if (r)
		goto out_unlink;
	r = arflex_sys_mmap(&base, len, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
	if (r)
		goto out_unlink;
	arflex_sys_close(fd);

	h = base;
	h->abi_major = ARFLEX_PORT_ABI_MAJOR;
	h->abi_minor = ARFLEX_PORT_ABI_MINOR;
	h->header_size = ARFLEX_PORT_HDR_SIZE;
	h->size = len;
	h->method = spec->method;
	h->elem_size = spec->type.elem_size;
	h->depth = spec->method == ARFLEX_PORT_STATE ? 1 : spec->depth;
	h->overflow = spec->method == ARFLEX_PORT_STREAM ? spec->overflow : 0;
	h->slot_stride = stride_of(spec->type.elem_size);
	h->type_major = spec->type.major;
	h->type_minor = spec->type.minor;
	h->type_hash = arflex_port_type_hash(spec->type.name);
	strncpy(h->type_name, spec->type.name, sizeof(h->type_name) - 1);
	STORE(&h->magic, ARFLEX_PORT_MAGIC);

	p->base = base;
	p->len = len;
	p->writable = true;
	p->owner = true;
	strcpy(p->name, shm_name);
	bind_view(p);
	return 0;

out_unlink:
	arflex_sys_close(fd);
	arflex_sys_shm_unlink(shm_name);
	return r;
}

int arflex_port_destroy(struct arflex_port *p)
{
	int r = 0;

	if (p->base)
		arflex_sys_munmap(p->base, p->len);
	if (p->owner)
		r = arflex_sys_shm_unlink(p->name);
	memset(p, 0, sizeof(*p));
	return r;
}

static int check_hdr(const struct arflex_port_hdr *h, size_t len, bool producer,
		     enum arflex_port_method method, const struct arflex_port_type *t)
{
	if (LOAD(&h->magic) != ARFLEX_PORT_MAGIC || h->abi_major != ARFLEX_PORT_ABI_MAJOR ||
	    h->header_size != ARFLEX_PORT_HDR_SIZE)
		return -EPROTO;
	if (h->size != len || h->slot_stride != stride_of(h->elem_size) || h->depth == 0 ||
	    ARFLEX_PORT_HDR_SIZE + (uint64_t)h->depth * h->slot_stride > len)
		return -EMSGSIZE;
	if (h->method != (uint32_t)method)
		return -EPROTOTYPE;
	if (method == ARFLEX_PORT_STATE && h->depth != 1)
		return -EPROTO;
	if (method == ARFLEX_PORT_STREAM && h->overflow != ARFLEX_OVERFLOW_DROP_OLDEST &&
	    h->overflow != ARFLEX_OVERFLOW_DROP_NEWEST)
		return -EPROTO;
	if (!t)
		return 0;
	if (h->type_hash != arflex_port_type_hash(t->name) || h->type_major != t->major)
		return -EPROTOTYPE;
	if (producer) {
		if (h->type_minor != t->minor || h->elem_size != t->elem_size)
			return -EPROTOTYPE;
	} else if (h->type_minor < t->minor || h->elem_size < t->elem_size) {
		return -EPROTOTYPE;
	}
	return 0;
}

int arflex_port_open(struct arflex_port *p, const char *shm_name, bool writable,
		     bool producer, enum arflex_port_method method,
		     const struct arflex_port_type *expect)
{
	struct stat st;
	void *base;
	int fd, r;

	memset(p, 0, sizeof(*p));
	if (!shm_name || strlen(shm_name) >= sizeof(p->name))
		return -EINVAL;
	fd = arflex_sys_shm_open(shm_name, writable ? O_RDWR : O_RDONLY, 0);
	if (fd < 0)
		return fd;
	r = arflex_sys_fstat(fd, &st);
	if (r)
		goto out_close;
	if ((size_t)st.st_size < ARFLEX_PORT_HDR_SIZE) {
		r = -EPROTO;
		goto out_close;
	}
	r = arflex_sys_mmap(&base, (size_t)st.st_size,
			    writable ? PROT_READ | PROT_WRITE : PROT_READ, MAP_SHARED, fd, 0);
	if (r)
		goto out_close;
	r = check_hdr(base, (size_t)st.st_size, producer, method, expect);
	if (r)
		goto out_unmap;
	arflex_sys_close(fd);
	p->base = base;
	p->len = (size_t)st.st_size;
	p->writable = writable;
	strcpy(p->name, shm_name);
	bind_view(p);
	if (producer) {
		p->next_idx = LOAD(&p->hdr->head);
		STORE(&p->hdr->writer_pid, (int32_t)getpid());
	} else if (writable && method == ARFLEX_PORT_STREAM) {
		STORE(&p->hdr->reader_pid, (int32_t)getpid());
	}
	return 0;

out_unmap:
	arflex_sys_munmap(base, (size_t)st.st_size);
out_close:
	arflex_sys_close(fd);
	return r;
}

void arflex_port_close(struct arflex_port *p)
{
	if (p->base)
		arflex_sys_munmap(p->base, p->len);
	memset(p, 0, sizeof(*p));
}

static inline struct arflex_slot_hdr *slot(const struct arflex_port *p, uint64_t idx)
{
	return (struct arflex_slot_hdr *)(p->slots + (idx % p->depth) * p->stride);
}

/* Copy helpers: payload bytes are accessed as plain memory inside the seqlock window; the
 * seq re-check discards any torn copy. */
static void slot_write(struct arflex_port *p, uint64_t idx, const void *val, size_t len,
		       uint64_t stamp)
{
	struct arflex_slot_hdr *s = slot(p, idx);

	STORER(&s->seq, 2 * idx + 1);
	__atomic_thread_fence(__ATOMIC_RELEASE);
	memcpy(s + 1, val, len);
	STORER(&s->stamp_ns, stamp);
	STORER(&s->length, (uint32_t)len);
	STORE(&s->seq, 2 * idx + 2);
}

int arflex_state_write_at(struct arflex_port *p, const void *val, size_t len, uint64_t stamp_ns)
{
	if (!p->hdr || !p->writable || p->method != ARFLEX_PORT_STATE || len > p->elem_size)
		return -EINVAL;
	slot_write(p, p->next_idx, val, len, stamp_ns);
	p->next_idx++;
	STORE(&p->hdr->head, p->next_idx);
	STORE(&p->hdr->written, p->next_idx);
	return 0;
}

int arflex_state_write(struct arflex_port *p, const void *val, size_t len)
{
	/* the clock is read before the write window opens: readers retry less */
	return arflex_state_write_at(p, val, len, arflex_sys_now_ns());
}

/* The identification cannot change while mapped: anything else is damage (an overwritten
 * header). Relaxed loads of one cache line, cheap enough for every read. */
static inline bool hdr_intact(const struct arflex_port *p)
{
	return LOADR(&p->hdr->magic) == ARFLEX_PORT_MAGIC && LOADR(&p->hdr->method) == p->method &&
	       LOADR(&p->hdr->slot_stride) == p->stride && LOADR(&p->hdr->depth) == p->depth;
}

int arflex_port_age(const struct arflex_port *p, uint64_t now_ns, uint64_t *age_ns)
{
	const struct arflex_slot_hdr *s;
	uint64_t head, stamp;

	if (!p->hdr || !age_ns)
		return -EINVAL;
	if (!hdr_intact(p))
		return -EPROTO;
	head = LOAD(&p->hdr->head);
	if (head == 0)
		return -ENODATA;
	s = slot(p, head - 1);
	stamp = LOAD(&s->stamp_ns);
	*age_ns = now_ns > stamp ? now_ns - stamp : 0;
	return 0;
}

int arflex_state_read(struct arflex_port *p, void *out, size_t len, uint64_t *seq)
{
	struct arflex_slot_hdr *s;

	if (!p->hdr || p->method != ARFLEX_PORT_STATE || len > p->elem_size)
		return -EINVAL;
	if (!hdr_intact(p))
		return -EPROTO;
	s = slot(p, 0);
	for (int i = 0; i < ARFLEX_STATE_READ_RETRIES; i++) {
		uint64_t s1 = LOAD(&s->seq), s2;

		if (s1 & 1)
			continue;
		if (s1 == p->last_seq)
			return 0;
		memcpy(out, s + 1, len);
		__atomic_thread_fence(__ATOMIC_ACQUIRE);
		s2 = LOADR(&s->seq);
		if (s1 == s2) {
			p->last_seq = s1;
			if (seq)
				*seq = s1 / 2;
			return 1;
		}
	}
	return 0;
}

int arflex_stream_push(struct arflex_port *p, const void *val, size_t len)
{
	struct arflex_port_hdr *h = p->hdr;
	uint64_t idx;

	if (!h || !p->writable || p->method != ARFLEX_PORT_STREAM || len > p->elem_size)
		return -EINVAL;
	/* written is counted last, after the push took effect (dropped or published): a reader
	 * that sees written == N then sees every outcome of the first N pushes, so
	 * delivered + dropped + lost + (head - tail) == written holds for it. */
	idx = p->next_idx;
	if (p->overflow == ARFLEX_OVERFLOW_DROP_NEWEST && idx - LOAD(&h->tail) >= p->depth) {
		STORE(&h->dropped, LOADR(&h->dropped) + 1);
		STORE(&h->written, LOADR(&h->written) + 1);
		return 0;
	}
	slot_write(p, idx, val, len, arflex_sys_now_ns()); /* before the write window */
	p->next_idx = idx + 1;
	STORE(&h->head, idx + 1);
	STORE(&h->written, LOADR(&h->written) + 1);
	return 1;
}

int arflex_stream_pop(struct arflex_port *p, void *out, size_t len)
{
	struct arflex_port_hdr *h = p->hdr;
	uint64_t head, tail;

	if (!h || !p->writable || p->method != ARFLEX_PORT_STREAM || len > p->elem_size)
		return -EINVAL;
	if (!hdr_intact(p))
		return -EPROTO;
	tail = LOADR(&h->tail);
	for (;;) {
		struct arflex_slot_hdr *s;
		uint64_t s1, s2;

		head = LOAD(&h->head);
		if (tail >= head)
			return 0;
		if (head - tail > p->depth) {
			STORE(&h->lost, LOADR(&h->lost) + (head - p->depth - tail));
			tail = head - p->depth;
			STORE(&h->tail, tail);
		}
		s = slot(p, tail);
		s1 = LOAD(&s->seq);
		if (s1 == 2 * tail + 2) {
			memcpy(out, s + 1, len);
			__atomic_thread_fence(__ATOMIC_ACQUIRE);
			s2 = LOADR(&s->seq);
			if (s1 == s2) {
				STORE(&h->delivered, LOADR(&h->delivered) + 1);
				STORE(&h->tail, tail + 1);
				return 1;
			}
		} else if (s1 < 2 * tail + 2) {
			/* published head but slot not yet visible: cannot happen with release
			 * ordering; treat as empty for now */
			return 0;
		}
		/* overwritten by drop-oldest while (or before) we looked */
		STORE(&h->lost, LOADR(&h->lost) + 1);
		tail++;
		STORE(&h->tail, tail);
	}
}

int arflex_stream_peek(const struct arflex_port *p, void *out, size_t len)
{
	const struct arflex_port_hdr *h = p->hdr;
	uint64_t head;

	if (!h || p->method != ARFLEX_PORT_STREAM || len > p->elem_size)
		return -EINVAL;
	if (!hdr_intact(p))
		return -EPROTO;
	head = LOAD(&h->head);
	if (!head)
		return 0;
	{
		struct arflex_slot_hdr *s = slot(p, head - 1);
		uint64_t s1 = LOAD(&s->seq), s2;

		if (s1 != 2 * (head - 1) + 2)
			return 0;
		memcpy(out, s + 1, len);
		__atomic_thread_fence(__ATOMIC_ACQUIRE);
		s2 = LOADR(&s->seq);
		return s1 == s2;
	}
}

void arflex_stream_counts(const struct arflex_port *p, struct arflex_stream_counts *c)
{
	const struct arflex_port_hdr *h = p->hdr;

	c->written = LOAD(&h->written);
	c->published = LOAD(&h->head);
	c->dropped = LOAD(&h->dropped);
	c->delivered = LOAD(&h->delivered);
	c->lost = LOAD(&h->lost);
	c->tail = LOAD(&h->tail);
}

void *arflex_frame_begin(struct arflex_port *p)
{
	struct arflex_slot_hdr *s;

	if (!p->hdr || !p->writable || p->method != ARFLEX_PORT_FRAME)
		return NULL;
	s = slot(p, p->next_idx);
	STORER(&s->seq, 2 * p->next_idx + 1);
	__atomic_thread_fence(__ATOMIC_RELEASE);
	return s + 1;
}

int arflex_frame_commit(struct arflex_port *p, uint32_t length)
{
	struct arflex_slot_hdr *s;
	int r = 0;

	if (!p->hdr || !p->writable || p->method != ARFLEX_PORT_FRAME)
		return -EINVAL;
	if (length > p->elem_size) {
		length = p->elem_size;
		r = -EINVAL;
	}
	s = slot(p, p->next_idx);
	STORER(&s->stamp_ns, arflex_sys_now_ns());
	STORER(&s->length, length);
	STORE(&s->seq, 2 * p->next_idx + 2);
	p->next_idx++;
	STORE(&p->hdr->head, p->next_idx);
	STORE(&p->hdr->written, p->next_idx);
	return r;
}

int arflex_frame_acquire(struct arflex_port *p, struct arflex_frame_view *v)
{
	uint64_t head, idx, seen;
	struct arflex_slot_hdr *s;
	uint64_t s1;

	if (!p->hdr || p->method != ARFLEX_PORT_FRAME)
		return -EINVAL;
	if (!hdr_intact(p))
		return -EPROTO;
	head = LOAD(&p->hdr->head);
	seen = p->last_seq; /* frames lent so far are [0, seen) */
	if (head == 0 || head <= seen)
		return 0;
	idx = head - 1;
	s = slot(p, idx);
	s1 = LOAD(&s->seq);
	if (s1 != 2 * idx + 2)
		return 0;
	v->data = s + 1;
	v->length = LOADR(&s->length);
	if (v->length > p->elem_size)
		v->length = p->elem_size;
	v->stamp_ns = LOADR(&s->stamp_ns);
	v->index = idx;
	v->skipped = idx - seen;
	v->slot_ = s;
	v->seq_ = s1;
	p->last_seq = idx + 1;
	return 1;
}

bool arflex_frame_valid(const struct arflex_frame_view *v)
{
	__atomic_thread_fence(__ATOMIC_ACQUIRE);
	return v->slot_ && LOADR(&v->slot_->seq) == v->seq_;
}
