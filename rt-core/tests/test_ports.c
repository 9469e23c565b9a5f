/* Ports under a writer and readers in separate processes. */
#include <errno.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#include "arflex/port.h"
#include "helper.h"

#define UPDATES 1000000u
#define READERS 2

struct sample {
	uint64_t seq;
	uint64_t data[6];
	uint64_t check;
};

static const struct arflex_port_type sample_type = {
	.name = "test.Sample", .major = 1, .minor = 0, .elem_size = sizeof(struct sample),
};

static void fill(struct sample *s, uint64_t i)
{
	s->seq = i;
	s->check = i * 0x9e3779b97f4a7c15u;
	for (int k = 0; k < 6; k++) {
		s->data[k] = (i + (uint64_t)k) * 0xff51afd7ed558ccdu;
		s->check ^= s->data[k];
	}
}

static bool intact(const struct sample *s)
{
	uint64_t c = s->seq * 0x9e3779b97f4a7c15u;

	for (int k = 0; k < 6; k++) {
		if (s->data[k] != (s->seq + (uint64_t)k) * 0xff51afd7ed558ccdu)
			return false;
		c ^= s->data[k];
	}
	return c == s->check;
}

static char rid[64];

static void name_of(char *buf, const char *port)
{
	snprintf(buf, ARFLEX_OBJ_NAME_SIZE, "/arflex.%s.w.out.%s", rid, port);
}

/* Child: state reader. Exit 0 when it saw the final value with no torn or backwards read. */
static int state_reader(const char *name)
{
	struct arflex_port p;
	struct sample s;
	uint64_t last = 0, seq, reads = 0;

	if (arflex_port_open(&p, name, false, false, ARFLEX_PORT_STATE, &sample_type))
		return 10;
	for (;;) {
		int r = arflex_state_read(&p, &s, sizeof(s), &seq);

		if (r < 0)
			return 11;
		if (r == 0)
			continue;
		reads++;
		if (!intact(&s))
			return 12; /* torn */
		if (s.seq + 1 != seq || s.seq < last)
			return 13; /* out of order / seq mismatch */
		if (last && s.seq == last)
			return 14; /* "new" value that is not new */
		last = s.seq;
		if (s.seq == UPDATES - 1)
			break;
	}
	arflex_port_close(&p);
	return reads > 0 ? 0 : 15;
}

static int state_writer(const char *name)
{
	struct arflex_port p;
	struct sample s;

	if (arflex_port_open(&p, name, true, true, ARFLEX_PORT_STATE, &sample_type))
		return 20;
	for (uint64_t i = 0; i < UPDATES; i++) {
		fill(&s, i);
		if (arflex_state_write(&p, &s, sizeof(s)))
			return 21;
	}
	arflex_port_close(&p);
	return 0;
}

static pid_t child(int (*fn)(const char *), const char *name)
{
	pid_t pid = fork();

	if (pid == 0)
		_exit(fn(name));
	assert_true(pid > 0);
	return pid;
}

static int wait_child(pid_t pid)
{
	int st;

	assert_int_equal(waitpid(pid, &st, 0), pid);
	return WIFEXITED(st) ? WEXITSTATUS(st) : 100 + WTERMSIG(st);
}

static void state_port_no_torn_no_lost(void **state)
{
	struct arflex_port_spec spec = { .method = ARFLEX_PORT_STATE, .type = sample_type };
	struct arflex_port mgr, dup;
	char name[ARFLEX_OBJ_NAME_SIZE];
	pid_t readers[READERS], writer;
	struct sample last;

	(void)state;
	th_rid(rid, sizeof(rid), "state");
	name_of(name, "pose");
	assert_int_equal(arflex_port_create(&mgr, name, &spec), 0);
	assert_int_equal(arflex_port_create(&dup, name, &spec), -EEXIST);

	for (int i = 0; i < READERS; i++)
		readers[i] = child(state_reader, name);
	writer = child(state_writer, name);
	assert_int_equal(wait_child(writer), 0);
	for (int i = 0; i < READERS; i++)
		assert_int_equal(wait_child(readers[i]), 0);
	assert_int_equal(mgr.hdr->head, UPDATES);
	mgr.last_seq = 0;
	assert_int_equal(arflex_state_read(&mgr, &last, sizeof(last), NULL), 1);
	assert_int_equal(last.seq, UPDATES - 1);
	assert_int_equal(arflex_port_destroy(&mgr), 0);
	th_assert_clean(rid);
}

/* A consumer judges freshness by the producer's write stamp: a producer that stops writing
 * ages, and a header damaged while mapped is reported, not read. */
static void port_age_and_header_recheck(void **state)
{
	struct arflex_port_spec spec = { .method = ARFLEX_PORT_STATE, .type = sample_type };
	struct arflex_port mgr, w, r;
	struct sample v;
	char name[ARFLEX_OBJ_NAME_SIZE];
	uint64_t age = 1, now;

	(void)state;
	th_rid(rid, sizeof(rid), "age");
	name_of(name, "x");
	assert_int_equal(arflex_port_create(&mgr, name, &spec), 0);
	assert_int_equal(arflex_port_open(&w, name, true, true, ARFLEX_PORT_STATE, &sample_type), 0);
	assert_int_equal(arflex_port_open(&r, name, false, false, ARFLEX_PORT_STATE, &sample_type), 0);
	assert_int_equal(arflex_port_age(&r, arflex_sys_now_ns(), &age), -ENODATA);
	fill(&v, 1);
	assert_int_equal(arflex_state_write(&w, &v, sizeof(v)), 0);
	now = arflex_sys_now_ns();
	assert_int_equal(arflex_port_age(&r, now, &age), 0);
	assert_true(age < 1000000000u);
	/* the same value, judged 250 ms later: 250 ms older */
	assert_int_equal(arflex_port_age(&r, now + 250000000u, &age), 0);
	assert_true(age >= 250000000u && age < 1250000000u);
	/* a stamp in the future (clock read before the write) is age 0, never negative */
	assert_int_equal(arflex_port_age(&r, 0, &age), 0);
	assert_int_equal(age, 0);
	/* damage: magic, then geometry */
	mgr.hdr->magic ^= 1;
	assert_int_equal(arflex_port_age(&r, now, &age), -EPROTO);
	mgr.hdr->magic ^= 1;
	assert_int_equal(arflex_port_age(&r, now, &age), 0);
	mgr.hdr->slot_stride += 64;
	assert_int_equal(arflex_port_age(&r, now, &age), -EPROTO);
	mgr.hdr->slot_stride -= 64;
	arflex_port_close(&r);
	arflex_port_close(&w);
	assert_int_equal(arflex_port_destroy(&mgr), 0);
	th_assert_clean(rid);
}

static void port_open_checks_type(void **state)
{
	struct arflex_port_spec spec = { .method = ARFLEX_PORT_STATE, .type = sample_type };
	struct arflex_port_type t = sample_type;
	struct arflex_port mgr, p;
	char name[ARFLEX_OBJ_NAME_SIZE];

	(void)state;
	th_rid(rid, sizeof(rid), "type");
	name_of(name, "x");
	spec.type.minor = 2;
	spec.type.elem_size = sizeof(struct sample) + 8;
	assert_int_equal(arflex_port_create(&mgr, name, &spec), 0);
	/* consumer of 1.0 with a smaller element: accepted */
	assert_int_equal(arflex_port_open(&p, name, false, false, ARFLEX_PORT_STATE, &t), 0);
	arflex_port_close(&p);
	/* producer must match exactly */
	assert_int_equal(arflex_port_open(&p, name, true, true, ARFLEX_PORT_STATE, &t),
			 -EPROTOTYPE);
	t.minor = 3;
	assert_int_equal(arflex_port_open(&p, name, false, false, ARFLEX_PORT_STATE, &t),
			 -EPROTOTYPE);
	t = sample_type;
	t.major = 2;
	assert_int_equal(arflex_port_open(&p, name, false, false, ARFLEX_PORT_STATE, &t),
			 -EPROTOTYPE);
	t = sample_type;
	t.name = "test.Other";
	assert_int_equal(arflex_port_open(&p, name, false, false, ARFLEX_PORT_STATE, &t),
			 -EPROTOTYPE);
	assert_int_equal(arflex_port_open(&p, name, false, false, ARFLEX_PORT_STREAM, NULL),
			 -EPROTOTYPE);
	mgr.hdr->magic ^= 1;
	assert_int_equal(arflex_port_open(&p, name, false, false, ARFLEX_PORT_STATE, NULL),
			 -EPROTO);
	assert_int_equal(arflex_port_destroy(&mgr), 0);
	assert_int_equal(arflex_port_open(&p, name, false, false, ARFLEX_PORT_STATE, NULL),
			 -ENOENT);
	th_assert_clean(rid);
}

static int stream_consumer(const char *name)
{
	struct arflex_port p;
	struct sample s;
	struct arflex_stream_counts c;
	uint64_t got = 0, last = 0;
	bool first = true;

	if (arflex_port_open(&p, name, true, false, ARFLEX_PORT_STREAM, &sample_type))
		return 30;
	for (;;) {
		int r = arflex_stream_pop(&p, &s, sizeof(s));

		if (r < 0)
			return 31;
		if (r == 1) {
			if (!intact(&s))
				return 32;
			if (!first && s.seq <= last)
				return 33; /* duplicate or reordered */
			first = false;
			last = s.seq;
			got++;
			continue;
		}
		arflex_stream_counts(&p, &c);
		if (c.written == UPDATES && c.tail == c.published)
			break;
	}
	arflex_stream_counts(&p, &c);
	if (c.delivered != got)
		return 34;
	arflex_port_close(&p);
	return 0;
}

static int stream_producer(const char *name)
{
	struct arflex_port p;
	struct sample s;

	if (arflex_port_open(&p, name, true, true, ARFLEX_PORT_STREAM, &sample_type))
		return 40;
	for (uint64_t i = 0; i < UPDATES; i++) {
		fill(&s, i);
		if (arflex_stream_push(&p, &s, sizeof(s)) < 0)
			return 41;
	}
	arflex_port_close(&p);
	return 0;
}

static void stream_counts_exact(enum arflex_port_overflow policy, const char *tag)
{
	struct arflex_port_spec spec = {
		.method = ARFLEX_PORT_STREAM, .type = sample_type, .depth = 64, .overflow = policy,
	};
	struct arflex_port mgr;
	struct arflex_stream_counts c;
	char name[ARFLEX_OBJ_NAME_SIZE];
	pid_t prod, cons;

	th_rid(rid, sizeof(rid), tag);
	name_of(name, "events");
	assert_int_equal(arflex_port_create(&mgr, name, &spec), 0);
	cons = child(stream_consumer, name);
	prod = child(stream_producer, name);
	assert_int_equal(wait_child(prod), 0);
	assert_int_equal(wait_child(cons), 0);
	arflex_stream_counts(&mgr, &c);
	print_message("%s: written %llu delivered %llu dropped %llu lost %llu\n", tag,
		      (unsigned long long)c.written, (unsigned long long)c.delivered,
		      (unsigned long long)c.dropped, (unsigned long long)c.lost);
	assert_int_equal(c.written, UPDATES);
	assert_int_equal(c.delivered + c.dropped + c.lost, UPDATES);
	assert_true(c.delivered > 0);
	if (policy == ARFLEX_OVERFLOW_DROP_NEWEST)
		assert_int_equal(c.lost, 0);
	else
		assert_int_equal(c.dropped, 0);
	assert_int_equal(arflex_port_destroy(&mgr), 0);
	th_assert_clean(rid);
}

static void stream_drop_newest_exact_counts(void **state)
{
	(void)state;
	stream_counts_exact(ARFLEX_OVERFLOW_DROP_NEWEST, "newest");
}

static void stream_drop_oldest_exact_counts(void **state)
{
	(void)state;
	stream_counts_exact(ARFLEX_OVERFLOW_DROP_OLDEST, "oldest");
}

/* Every state read re-checks the mapped header: an overwritten magic or geometry is -EPROTO
 * (the value is not copied), and reads resume once the header is restored. */
static void state_read_refuses_a_damaged_header(void **state)
{
	struct arflex_port_spec spec = { .method = ARFLEX_PORT_STATE, .type = sample_type };
	struct arflex_port mgr, w, r;
	struct sample v, got;
	char name[ARFLEX_OBJ_NAME_SIZE];

	(void)state;
	th_rid(rid, sizeof(rid), "hdr");
	name_of(name, "x");
	assert_int_equal(arflex_port_create(&mgr, name, &spec), 0);
	assert_int_equal(arflex_port_open(&w, name, true, true, ARFLEX_PORT_STATE, &sample_type), 0);
	assert_int_equal(arflex_port_open(&r, name, false, false, ARFLEX_PORT_STATE, &sample_type), 0);
	fill(&v, 1);
	assert_int_equal(arflex_state_write(&w, &v, sizeof(v)), 0);
	mgr.hdr->magic = 0;
	memset(&got, 0, sizeof(got));
	assert_int_equal(arflex_state_read(&r, &got, sizeof(got), NULL), -EPROTO);
	assert_int_equal(got.seq, 0); /* not copied */
	mgr.hdr->magic = ARFLEX_PORT_MAGIC;
	assert_int_equal(arflex_state_read(&r, &got, sizeof(got), NULL), 1);
	assert_true(intact(&got));
	mgr.hdr->depth = 2;
	fill(&v, 2);
	assert_int_equal(arflex_state_write(&w, &v, sizeof(v)), 0);
	assert_int_equal(arflex_state_read(&r, &got, sizeof(got), NULL), -EPROTO);
	mgr.hdr->depth = 1;
	assert_int_equal(arflex_state_read(&r, &got, sizeof(got), NULL), 1);
	assert_true(intact(&got));
	arflex_port_close(&r);
	arflex_port_close(&w);
	assert_int_equal(arflex_port_destroy(&mgr), 0);
	th_assert_clean(rid);
}

/* Stream and frame readers re-check the header as state readers do: damage is -EPROTO,
 * nothing is consumed or lent, and reads go on once the header is restored. */
static void stream_and_frame_reads_refuse_a_damaged_header(void **state)
{
	struct arflex_port_spec ss = {
		.method = ARFLEX_PORT_STREAM, .type = sample_type, .depth = 4,
		.overflow = ARFLEX_OVERFLOW_DROP_NEWEST,
	};
	struct arflex_port_spec fs = {
		.method = ARFLEX_PORT_FRAME, .type = { "test.Frame", 1, 0, 64 }, .depth = 2,
	};
	const struct arflex_port_type ft = { "test.Frame", 1, 0, 64 };
	struct arflex_port q, f, fr;
	struct arflex_frame_view v;
	struct sample s;
	char qn[ARFLEX_OBJ_NAME_SIZE], fn[ARFLEX_OBJ_NAME_SIZE];

	(void)state;
	th_rid(rid, sizeof(rid), "hdr2");
	name_of(qn, "q");
	name_of(fn, "image");
	assert_int_equal(arflex_port_create(&q, qn, &ss), 0);
	fill(&s, 1);
	assert_int_equal(arflex_stream_push(&q, &s, sizeof(s)), 1);
	q.hdr->magic ^= 1;
	assert_int_equal(arflex_stream_pop(&q, &s, sizeof(s)), -EPROTO);
	assert_int_equal(arflex_stream_peek(&q, &s, sizeof(s)), -EPROTO);
	q.hdr->magic ^= 1;
	q.hdr->slot_stride += 64;
	assert_int_equal(arflex_stream_pop(&q, &s, sizeof(s)), -EPROTO);
	q.hdr->slot_stride -= 64;
	assert_int_equal(arflex_stream_pop(&q, &s, sizeof(s)), 1); /* nothing was consumed */
	assert_int_equal(s.seq, 1);
	assert_int_equal(arflex_port_destroy(&q), 0);

	assert_int_equal(arflex_port_create(&f, fn, &fs), 0);
	assert_int_equal(arflex_port_open(&fr, fn, false, false, ARFLEX_PORT_FRAME, &ft), 0);
	memset(arflex_frame_begin(&f), 7, 64);
	assert_int_equal(arflex_frame_commit(&f, 64), 0);
	f.hdr->depth = 3;
	assert_int_equal(arflex_frame_acquire(&fr, &v), -EPROTO);
	f.hdr->depth = 2;
	assert_int_equal(arflex_frame_acquire(&fr, &v), 1); /* nothing was lent before */
	assert_int_equal(v.index, 0);
	assert_true(arflex_frame_valid(&v));
	arflex_port_close(&fr);
	assert_int_equal(arflex_port_destroy(&f), 0);
	th_assert_clean(rid);
}

static void stream_single_process_semantics(void **state)
{
	struct arflex_port_spec spec = {
		.method = ARFLEX_PORT_STREAM, .type = sample_type, .depth = 4,
		.overflow = ARFLEX_OVERFLOW_DROP_OLDEST,
	};
	struct arflex_port mgr;
	struct sample s;
	char name[ARFLEX_OBJ_NAME_SIZE];

	(void)state;
	th_rid(rid, sizeof(rid), "sp");
	name_of(name, "q");
	assert_int_equal(arflex_port_create(&mgr, name, &spec), 0);
	for (uint64_t i = 0; i < 10; i++) {
		fill(&s, i);
		assert_int_equal(arflex_stream_push(&mgr, &s, sizeof(s)), 1);
	}
	assert_int_equal(arflex_stream_peek(&mgr, &s, sizeof(s)), 1);
	assert_int_equal(s.seq, 9);
	for (uint64_t i = 6; i < 10; i++) {
		assert_int_equal(arflex_stream_pop(&mgr, &s, sizeof(s)), 1);
		assert_int_equal(s.seq, i); /* the 4 newest survive, oldest first */
	}
	assert_int_equal(arflex_stream_pop(&mgr, &s, sizeof(s)), 0);
	assert_int_equal(mgr.hdr->lost, 6);
	assert_int_equal(arflex_port_destroy(&mgr), 0);

	spec.overflow = ARFLEX_OVERFLOW_DROP_NEWEST;
	assert_int_equal(arflex_port_create(&mgr, name, &spec), 0);
	for (uint64_t i = 0; i < 10; i++) {
		fill(&s, i);
		assert_int_equal(arflex_stream_push(&mgr, &s, sizeof(s)), i < 4 ? 1 : 0);
	}
	for (uint64_t i = 0; i < 4; i++) {
		assert_int_equal(arflex_stream_pop(&mgr, &s, sizeof(s)), 1);
		assert_int_equal(s.seq, i); /* the 4 oldest kept */
	}
	assert_int_equal(mgr.hdr->dropped, 6);
	assert_int_equal(arflex_port_destroy(&mgr), 0);
	th_assert_clean(rid);
}

#define FRAME_BYTES (256u * 1024u)
#define FRAMES 3000u

static int frame_reader(const char *name)
{
	const struct arflex_port_type t = { "test.Frame", 1, 0, FRAME_BYTES };
	struct arflex_port p;
	struct arflex_frame_view v;
	uint64_t valid = 0, last = 0;
	bool first = true;

	if (arflex_port_open(&p, name, false, false, ARFLEX_PORT_FRAME, &t))
		return 50;
	for (;;) {
		int r = arflex_frame_acquire(&p, &v);
		const uint32_t *w;
		bool ok = true;

		if (r < 0)
			return 51;
		if (r == 0) {
			if (__atomic_load_n(&p.hdr->head, __ATOMIC_ACQUIRE) == FRAMES)
				break;
			continue;
		}
		if (!first && v.index <= last)
			return 52;
		first = false;
		last = v.index;
		w = v.data;
		for (uint32_t k = 0; k < v.length / 4; k += 997)
			if (w[k] != (uint32_t)v.index + k)
				ok = false;
		if (arflex_frame_valid(&v)) {
			if (!ok || v.length != FRAME_BYTES)
				return 53; /* validated but wrong: a real error */
			valid++;
		}
	}
	arflex_port_close(&p);
	return valid > 0 ? 0 : 54;
}

static int frame_writer(const char *name)
{
	const struct arflex_port_type t = { "test.Frame", 1, 0, FRAME_BYTES };
	struct arflex_port p;

	if (arflex_port_open(&p, name, true, true, ARFLEX_PORT_FRAME, &t))
		return 60;
	for (uint32_t i = 0; i < FRAMES; i++) {
		uint32_t *w = arflex_frame_begin(&p);

		for (uint32_t k = 0; k < FRAME_BYTES / 4; k++)
			w[k] = i + k;
		if (arflex_frame_commit(&p, FRAME_BYTES))
			return 61;
	}
	arflex_port_close(&p);
	return 0;
}

static void frame_port_zero_copy(void **state)
{
	struct arflex_port_spec spec = {
		.method = ARFLEX_PORT_FRAME, .type = { "test.Frame", 1, 0, FRAME_BYTES }, .depth = 4,
	};
	struct arflex_port mgr;
	char name[ARFLEX_OBJ_NAME_SIZE];
	pid_t r, w;

	(void)state;
	th_rid(rid, sizeof(rid), "frame");
	name_of(name, "image");
	assert_int_equal(arflex_port_create(&mgr, name, &spec), 0);
	r = child(frame_reader, name);
	w = child(frame_writer, name);
	assert_int_equal(wait_child(w), 0);
	assert_int_equal(wait_child(r), 0);
	assert_int_equal(mgr.hdr->head, FRAMES);
	assert_int_equal(arflex_port_destroy(&mgr), 0);
	th_assert_clean(rid);
}

/* Port ABI 2.0 (DECISIONS.md D30): the segment says 2.0, slot k is at 256 + k * stride with
 * stride = round_up(24 + elem_size, 64), the payload follows the 24-byte slot header (a value
 * of up to 40 bytes shares the seqlock word's cache line), for every method; a 1.x segment (or
 * any other major) is refused on open, by producers and consumers alike. */
static void port_abi_2_layout_and_1x_refused(void **state)
{
	static const struct {
		uint32_t elem, stride;
	} geo[] = { { 1, 64 }, { 8, 64 }, { 40, 64 }, { 41, 128 }, { 64, 128 }, { 104, 128 },
		    { 105, 192 } };
	struct arflex_port_spec spec = { .method = ARFLEX_PORT_STATE, .type = sample_type };
	struct arflex_port_type t8 = { .name = "test.Stamp", .major = 1, .minor = 0, .elem_size = 8 };
	struct arflex_port mgr, w, r, q, f;
	char name[ARFLEX_OBJ_NAME_SIZE];
	uint64_t v = UINT64_C(0x1122334455667788), got = 0, stored;
	uint8_t *slot0;

	(void)state;
	assert_int_equal(ARFLEX_SLOT_HDR_SIZE, 24);
	assert_int_equal(ARFLEX_SLOT_INLINE_MAX, 40);
	th_rid(rid, sizeof(rid), "abi2");
	for (size_t i = 0; i < sizeof(geo) / sizeof(geo[0]); i++) {
		char gname[ARFLEX_OBJ_NAME_SIZE], port[16];

		snprintf(port, sizeof(port), "g%zu", i);
		name_of(gname, port);
		spec.type.elem_size = geo[i].elem;
		assert_int_equal(arflex_port_segment_size(&spec), 4096);
		assert_int_equal(arflex_port_create(&mgr, gname, &spec), 0);
		assert_int_equal(mgr.hdr->slot_stride, geo[i].stride);
		assert_int_equal(mgr.hdr->abi_major, 2);
		assert_int_equal(mgr.hdr->abi_minor, 0);
		assert_int_equal(arflex_port_destroy(&mgr), 0);
	}

	/* a state value of 8 bytes sits at +24 of slot 0, in the line of its seq */
	name_of(name, "s");
	spec.type = t8;
	assert_int_equal(arflex_port_create(&mgr, name, &spec), 0);
	assert_int_equal(arflex_port_open(&w, name, true, true, ARFLEX_PORT_STATE, &t8), 0);
	assert_int_equal(arflex_port_open(&r, name, false, false, ARFLEX_PORT_STATE, &t8), 0);
	assert_int_equal(arflex_state_write(&w, &v, sizeof(v)), 0);
	slot0 = (uint8_t *)mgr.base + ARFLEX_PORT_HDR_SIZE;
	memcpy(&stored, slot0 + 24, sizeof(stored));
	assert_true(stored == v);
	assert_int_equal(((const struct arflex_slot_hdr *)slot0)->seq, 2);
	assert_int_equal(((const struct arflex_slot_hdr *)slot0)->length, 8);
	assert_int_equal(arflex_state_read(&r, &got, sizeof(got), NULL), 1);
	assert_true(got == v);
	/* arflex_state_write_at: the producer's own stamp, which freshness is judged by */
	{
		uint64_t t = arflex_sys_now_ns(), age = 0;

		assert_int_equal(arflex_state_write_at(&w, &t, sizeof(t), t), 0);
		assert_true(((const struct arflex_slot_hdr *)slot0)->stamp_ns == t);
		assert_int_equal(arflex_port_age(&r, t + 5000, &age), 0);
		assert_int_equal(age, 5000);
		assert_int_equal(arflex_state_read(&r, &got, sizeof(got), NULL), 1);
		assert_true(got == t);
		assert_int_equal(arflex_state_write_at(&r, &t, sizeof(t), t), -EINVAL);
		assert_int_equal(arflex_state_write_at(&w, &t, 9, t), -EINVAL);
	}
	arflex_port_close(&r);
	arflex_port_close(&w);

	/* a 1.x segment (the 1.2 layout had its payload at +64) and a future 3.x are refused */
	for (uint16_t major = 0; major <= 3; major++) {
		if (major == ARFLEX_PORT_ABI_MAJOR)
			continue;
		mgr.hdr->abi_major = major;
		mgr.hdr->abi_minor = 2;
		assert_int_equal(arflex_port_open(&r, name, false, false, ARFLEX_PORT_STATE, &t8),
				 -EPROTO);
		assert_int_equal(arflex_port_open(&w, name, true, true, ARFLEX_PORT_STATE, &t8),
				 -EPROTO);
		assert_int_equal(arflex_port_open(&r, name, false, false, ARFLEX_PORT_STATE, NULL),
				 -EPROTO);
	}
	/* a higher minor of the same major is accepted (minors only add in reserved space) */
	mgr.hdr->abi_major = ARFLEX_PORT_ABI_MAJOR;
	mgr.hdr->abi_minor = 7;
	assert_int_equal(arflex_port_open(&r, name, false, false, ARFLEX_PORT_STATE, &t8), 0);
	arflex_port_close(&r);
	assert_int_equal(arflex_port_destroy(&mgr), 0);

	/* streams and frames follow the same rule: element i of a stream at slot i mod depth, +24 */
	name_of(name, "q");
	spec = (struct arflex_port_spec){ .method = ARFLEX_PORT_STREAM, .type = t8, .depth = 4,
					  .overflow = ARFLEX_OVERFLOW_DROP_OLDEST };
	assert_int_equal(arflex_port_create(&mgr, name, &spec), 0);
	assert_int_equal(mgr.hdr->slot_stride, 64);
	assert_int_equal(arflex_port_open(&q, name, true, true, ARFLEX_PORT_STREAM, &t8), 0);
	for (uint64_t i = 0; i < 2; i++) {
		uint64_t x = v + i;

		assert_int_equal(arflex_stream_push(&q, &x, sizeof(x)), 1);
	}
	memcpy(&stored, (uint8_t *)mgr.base + ARFLEX_PORT_HDR_SIZE + 64 + 24, sizeof(stored));
	assert_true(stored == v + 1);
	arflex_port_close(&q);
	assert_int_equal(arflex_port_destroy(&mgr), 0);

	name_of(name, "f");
	spec = (struct arflex_port_spec){ .method = ARFLEX_PORT_FRAME,
					  .type = { "test.Frame", 1, 0, 1000 }, .depth = 2 };
	assert_int_equal(arflex_port_create(&mgr, name, &spec), 0);
	assert_int_equal(mgr.hdr->slot_stride, 1024);
	assert_int_equal(arflex_port_open(&f, name, true, true, ARFLEX_PORT_FRAME, NULL), 0);
	/* (the producer's own mapping: f.base) */
	assert_ptr_equal(arflex_frame_begin(&f), (uint8_t *)f.base + ARFLEX_PORT_HDR_SIZE + 24);
	assert_int_equal(arflex_frame_commit(&f, 10), 0);
	assert_ptr_equal(arflex_frame_begin(&f), (uint8_t *)f.base + ARFLEX_PORT_HDR_SIZE + 1024 + 24);
	arflex_port_close(&f);
	assert_int_equal(arflex_port_destroy(&mgr), 0);
	th_assert_clean(rid);
}

/* Issue 30 (D79): a FIFO or a directory someone put at a port's name is refused, never waited on. */
static void port_open_refuses_a_fifo_or_directory_at_the_name(void **state)
{
	struct arflex_port q;
	char name[ARFLEX_OBJ_NAME_SIZE], path[ARFLEX_OBJ_NAME_SIZE + 16];

	(void)state;
	th_rid(rid, sizeof(rid), "squat");
	name_of(name, "fifo");
	snprintf(path, sizeof(path), "/dev/shm%s", name);
	assert_int_equal(mkfifo(path, 0666), 0);
	/* a reader's open of a FIFO without O_NONBLOCK waits for a writer: this returns at once */
	assert_int_equal(arflex_port_open(&q, name, false, false, ARFLEX_PORT_STATE, NULL), -EPERM);
	assert_int_equal(unlink(path), 0);
	assert_int_equal(mkdir(path, 0777), 0);
	assert_int_equal(arflex_port_open(&q, name, false, false, ARFLEX_PORT_STATE, NULL), -EPERM);
	assert_int_equal(rmdir(path), 0);
	th_assert_clean(rid);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(port_open_refuses_a_fifo_or_directory_at_the_name),
		cmocka_unit_test(state_port_no_torn_no_lost),
		cmocka_unit_test(port_open_checks_type),
		cmocka_unit_test(port_age_and_header_recheck),
		cmocka_unit_test(state_read_refuses_a_damaged_header),
		cmocka_unit_test(stream_and_frame_reads_refuse_a_damaged_header),
		cmocka_unit_test(stream_single_process_semantics),
		cmocka_unit_test(stream_drop_newest_exact_counts),
		cmocka_unit_test(stream_drop_oldest_exact_counts),
		cmocka_unit_test(frame_port_zero_copy),
		cmocka_unit_test(port_abi_2_layout_and_1x_refused),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
