/*
 * arflex/port.h - data ports over POSIX shared memory.
 *
 * One segment per OUTPUT port: /arflex.<runtime-id>.<instance>.out.<port>, created by the
 * manager (arflex_port_create, O_CREAT|O_EXCL, mode 0600) and removed by it; the producing RT
 * process opens it read-write, consumers open it (stream: read-write, to advance their tail;
 * state/frame: read-only). The segment survives a restart of its producer. Byte layout: see
 * rt-core/docs/ABI.md; the structs below are that layout. Port segments carry their own layout
 * version (ARFLEX_PORT_ABI_MAJOR.MINOR in abi_major/abi_minor, 2.0 since DECISIONS.md D30);
 * control blocks and messages carry ARFLEX_ABI_MAJOR.MINOR.
 *
 * Slot layout (one rule for all three methods): slot k starts at ARFLEX_PORT_HDR_SIZE +
 * k * slot_stride (64-byte aligned); its 24-byte header (struct arflex_slot_hdr) is followed
 * directly by the payload; slot_stride = round_up(24 + elem_size, 64). A payload of up to
 * ARFLEX_SLOT_INLINE_MAX (40) bytes therefore shares the cache line of its seqlock word: a
 * state read of such a value touches one line. Payloads are 8-byte aligned.
 *
 * Three methods:
 *   STATE  latest value. Single writer, any number of readers. Seqlock on one slot: a reader
 *          never blocks the writer and never returns a torn value; if it fails
 *          ARFLEX_STATE_READ_RETRIES times in one call it reports "no new value" (0).
 *   STREAM bounded ring, single producer, SINGLE consumer (the binding rules guarantee one;
 *          monitors use arflex_stream_peek which does not consume). Overflow drop-newest: the
 *          producer refuses the new element and counts it in hdr.dropped. Drop-oldest: the
 *          producer overwrites the oldest slot; the consumer notices and counts it in
 *          hdr.lost. After the consumer drained the ring: delivered + dropped + lost == written.
 *   FRAME  ring of large slots with a per-slot sequence; the reader gets a pointer into the
 *          segment (no copy) and validates it after use.
 *
 * All functions here are non-blocking and allocation-free except create/open/close/destroy,
 * which map and unmap and must not be called on the RT thread after start.
 */
#ifndef ARFLEX_PORT_H
#define ARFLEX_PORT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "arflex/control.h"
#include "arflex/sys.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Magic of a port segment: bytes "ARFLXPRT" read as little-endian uint64. */
#define ARFLEX_PORT_MAGIC UINT64_C(0x545250584C465241)
/** Size of the segment header; the first slot starts here. */
#define ARFLEX_PORT_HDR_SIZE 256u
/** Version of the port segment layout (hdr.abi_major/abi_minor). A reader refuses a segment
 *  whose major differs (-EPROTO). 2.0: 24-byte slot header, payload right after it (D30). */
#define ARFLEX_PORT_ABI_MAJOR 2u
#define ARFLEX_PORT_ABI_MINOR 0u
/** Size of the header in front of each slot's payload; the payload starts right after it. */
#define ARFLEX_SLOT_HDR_SIZE 24u
/** Slots are aligned to (and their stride is a multiple of) one cache line. */
#define ARFLEX_SLOT_ALIGN 64u
/** Largest payload that shares its slot header's cache line. */
#define ARFLEX_SLOT_INLINE_MAX (ARFLEX_SLOT_ALIGN - ARFLEX_SLOT_HDR_SIZE)
/** Size of the type_name field. */
#define ARFLEX_TYPE_NAME_SIZE 64
/** A state reader gives up after this many torn attempts in one call. */
#define ARFLEX_STATE_READ_RETRIES 16
/** Upper bounds checked at create/open. */
#define ARFLEX_PORT_MAX_ELEM (64u << 20)
#define ARFLEX_PORT_MAX_DEPTH 65536u

/** Transport method (hdr.method). */
enum arflex_port_method {
	ARFLEX_PORT_STATE = 1,
	ARFLEX_PORT_STREAM = 2,
	ARFLEX_PORT_FRAME = 3,
};

/** Stream overflow policy (hdr.overflow); 0 for state and frame ports. */
enum arflex_port_overflow {
	ARFLEX_OVERFLOW_NONE = 0,
	ARFLEX_OVERFLOW_DROP_OLDEST = 1,
	ARFLEX_OVERFLOW_DROP_NEWEST = 2,
};

/** Segment header, 256 bytes at offset 0. Identification (0..127) is written by the manager
 *  at create and never changes; 128..191 is written by the producer only, 192..255 by the
 *  (single, stream) consumer only. */
struct arflex_port_hdr {
	uint64_t magic;        /**< ARFLEX_PORT_MAGIC */
	uint16_t abi_major;    /**< ARFLEX_PORT_ABI_MAJOR */
	uint16_t abi_minor;    /**< ARFLEX_PORT_ABI_MINOR */
	uint32_t header_size;  /**< ARFLEX_PORT_HDR_SIZE: offset of slot 0 */
	uint64_t size;         /**< segment size in bytes (page multiple) */
	uint32_t method;       /**< enum arflex_port_method */
	uint32_t elem_size;    /**< payload bytes per element (frame: max bytes per frame) */
	uint32_t depth;        /**< slots: 1 for state, ring depth for stream and frame */
	uint32_t overflow;     /**< enum arflex_port_overflow */
	uint32_t slot_stride;  /**< ARFLEX_SLOT_HDR_SIZE + elem_size rounded up to 64 */
	uint16_t type_major;   /**< port type version */
	uint16_t type_minor;
	uint64_t type_hash;    /**< FNV-1a 64 of the port type name (see arflex_port_type_hash) */
	char type_name[ARFLEX_TYPE_NAME_SIZE]; /**< NUL-terminated port type name */
	uint64_t reserved_id;
	/* producer section, 128 */
	uint64_t head;         /**< elements published (state: writes) */
	uint64_t written;      /**< push/write attempts ("sent") */
	uint64_t dropped;      /**< drop-newest: refused by the producer */
	int32_t writer_pid;    /**< pid of the producer that opened it last (0: none yet) */
	uint32_t reserved_p0;
	uint64_t reserved_p[4];
	/* consumer section, 192 (stream only) */
	uint64_t tail;         /**< elements consumed (delivered or lost) */
	uint64_t delivered;    /**< elements returned by arflex_stream_pop */
	uint64_t lost;         /**< drop-oldest: overwritten before the consumer read them */
	int32_t reader_pid;    /**< pid of the consumer */
	uint32_t reserved_c0;
	uint64_t reserved_c[4];
};

/** Header in front of each slot's payload, 24 bytes, the payload follows at +24 in the same
 *  cache line. seq is the slot's seqlock: for element index i (0-based count of writes) it is
 *  2*i+1 while being written and 2*i+2 when complete; 0 = never written. */
struct arflex_slot_hdr {
	uint64_t seq;
	uint64_t stamp_ns;     /**< CLOCK_MONOTONIC when the producer wrote it */
	uint32_t length;       /**< valid payload bytes (elem_size except for frames) */
	uint32_t reserved0;
};

ARFLEX_STATIC_ASSERT(sizeof(struct arflex_port_hdr) == ARFLEX_PORT_HDR_SIZE, "port hdr");
ARFLEX_STATIC_ASSERT(offsetof(struct arflex_port_hdr, type_hash) == 48, "port type_hash");
ARFLEX_STATIC_ASSERT(offsetof(struct arflex_port_hdr, head) == 128, "port head");
ARFLEX_STATIC_ASSERT(offsetof(struct arflex_port_hdr, tail) == 192, "port tail");
ARFLEX_STATIC_ASSERT(sizeof(struct arflex_slot_hdr) == ARFLEX_SLOT_HDR_SIZE, "slot hdr");
ARFLEX_STATIC_ASSERT(offsetof(struct arflex_slot_hdr, stamp_ns) == 8, "slot stamp_ns");
ARFLEX_STATIC_ASSERT(offsetof(struct arflex_slot_hdr, length) == 16, "slot length");
ARFLEX_STATIC_ASSERT(ARFLEX_SLOT_HDR_SIZE % 8 == 0 && ARFLEX_PORT_HDR_SIZE % ARFLEX_SLOT_ALIGN == 0,
		     "slot alignment");

/** What a port carries; used to create a segment and to check one on open. */
struct arflex_port_type {
	const char *name;      /**< port type name, e.g. "arflex.JointState" (< 64 bytes) */
	uint16_t major;        /**< type version */
	uint16_t minor;
	uint32_t elem_size;    /**< sizeof the C struct of the type (frame: max frame bytes) */
};

/** Parameters of a new segment (manager side). */
struct arflex_port_spec {
	enum arflex_port_method method;
	struct arflex_port_type type;
	uint32_t depth;                      /**< ignored for state ports (1) */
	enum arflex_port_overflow overflow;  /**< streams only */
};

/** A mapped port segment. Caller-owned storage; fields are private, read through functions. */
struct arflex_port {
	void *base;
	size_t len;
	struct arflex_port_hdr *hdr;
	uint8_t *slots;
	uint32_t stride;
	uint32_t depth;
	uint32_t elem_size;   /**< of the segment */
	uint32_t method;
	uint32_t overflow;
	bool writable;
	bool owner;           /**< created by us: destroy unlinks */
	uint64_t last_seq;    /**< reader: last seq returned (state/frame) */
	uint64_t next_idx;    /**< writer: next element index */
	char name[ARFLEX_OBJ_NAME_SIZE];
};

/** FNV-1a 64 (offset basis 0xcbf29ce484222325, prime 0x100000001b3) over the bytes of
 *  @name without its NUL. The Java side computes the same hash. */
ARFLEX_API uint64_t arflex_port_type_hash(const char *name);

/** A port name as contracts and the ABI allow it: [a-z0-9_]{1,31}. Predicate. */
ARFLEX_API bool arflex_port_name_valid(const char *name);

/** Segment size for @spec (header + depth slots, rounded up to 4096). 0 if invalid. */
ARFLEX_API size_t arflex_port_segment_size(const struct arflex_port_spec *spec);

/**
 * Manager side: creates @shm_name (O_CREAT|O_EXCL|O_RDWR, 0600), sizes, maps and formats it.
 * Returns 0 or -errno: -EINVAL bad spec or name, -EEXIST already exists, or the failing call's
 * error. On failure nothing is left behind.
 */
ARFLEX_API int arflex_port_create(struct arflex_port *p, const char *shm_name,
				  const struct arflex_port_spec *spec);

/** Manager side: unmaps and unlinks a port made by arflex_port_create. Returns 0 or the
 *  shm_unlink error. */
ARFLEX_API int arflex_port_destroy(struct arflex_port *p);

/**
 * Opens an existing segment (never creates it) and checks it against @expect (NULL: no type
 * check). @writable maps read-write (producers, stream consumers). For a producer
 * (@producer true) method, type hash, version and elem_size must match exactly; for a
 * consumer the provider's type major must equal, its minor be >= and its elem_size be >=
 * the expected ones. Returns 0 or -errno: -ENOENT, -EPROTO (bad magic, a port ABI major other
 * than ARFLEX_PORT_ABI_MAJOR, e.g. a 1.x segment, or a bad header),
 * -EPROTOTYPE (method or type mismatch), -EMSGSIZE (size mismatch).
 */
ARFLEX_API int arflex_port_open(struct arflex_port *p, const char *shm_name, bool writable,
				bool producer, enum arflex_port_method method,
				const struct arflex_port_type *expect);

/** Unmaps a port opened with arflex_port_open (does not unlink). */
ARFLEX_API void arflex_port_close(struct arflex_port *p);

/**
 * Freshness of a port as a consumer judges it: *@age_ns = @now_ns minus the producer's write
 * stamp of its newest element (0 if the stamp is in the future). A dead, stopped or hung
 * producer's last value keeps ageing, so a consumer that must not act on old data (a safety
 * input) compares the age with its limit every cycle. Also re-checks the segment header
 * (magic, method, geometry) against the mapping: a header overwritten while mapped reports
 * -EPROTO. Returns 0, -ENODATA (nothing written yet), -EPROTO, -EINVAL. RT safe.
 */
ARFLEX_API int arflex_port_age(const struct arflex_port *p, uint64_t now_ns, uint64_t *age_ns);

/* ---- state ----------------------------------------------------------------------- */

/** Writes @len (<= elem_size) bytes as the new value. Returns 0 or -EINVAL. RT safe. */
ARFLEX_API int arflex_state_write(struct arflex_port *p, const void *val, size_t len);

/**
 * As arflex_state_write, but the slot's stamp_ns is @stamp_ns, a CLOCK_MONOTONIC time
 * (arflex_sys_now_ns) the producer already took for this value (e.g. the value's own t_ns),
 * instead of a clock read inside the call: one clock read less between the producer's stamp
 * and the publication (about 30 ns on the development VM, D30). Consumers judge freshness by
 * it (arflex_port_age): pass a time taken before the call, never a later one. Returns 0 or
 * -EINVAL. RT safe.
 */
ARFLEX_API int arflex_state_write_at(struct arflex_port *p, const void *val, size_t len,
				     uint64_t stamp_ns);

/**
 * Reads the latest value into @out (@len <= elem_size bytes copied) if it is newer than the
 * one this handle returned last. Returns 1 (new value, *@seq = its write count if @seq is not
 * NULL), 0 (no new value, or the writer kept it busy for ARFLEX_STATE_READ_RETRIES attempts:
 * @out untouched), -EPROTO (the segment header no longer matches what was opened: magic,
 * method or geometry overwritten; @out untouched; reads succeed again once it is restored),
 * -EINVAL. RT safe.
 */
ARFLEX_API int arflex_state_read(struct arflex_port *p, void *out, size_t len, uint64_t *seq);

/* ---- stream ---------------------------------------------------------------------- */

/** Pushes one element. Returns 1 if published (drop-oldest may have overwritten the oldest),
 *  0 if dropped (drop-newest, ring full), -EINVAL. RT safe. */
ARFLEX_API int arflex_stream_push(struct arflex_port *p, const void *val, size_t len);

/** Pops the oldest unread element into @out. Returns 1, 0 (empty), -EPROTO (the segment
 *  header no longer matches what was opened, as for arflex_state_read: nothing consumed),
 *  -EINVAL. Single consumer. RT safe. */
ARFLEX_API int arflex_stream_pop(struct arflex_port *p, void *out, size_t len);

/** Copies the newest element without consuming (monitors). Returns 1, 0 (none/torn),
 *  -EPROTO (damaged header), -EINVAL. */
ARFLEX_API int arflex_stream_peek(const struct arflex_port *p, void *out, size_t len);

/** Counters (atomic snapshot of each). */
struct arflex_stream_counts {
	uint64_t written, published, dropped, delivered, lost, tail;
};
ARFLEX_API void arflex_stream_counts(const struct arflex_port *p,
				     struct arflex_stream_counts *c);

/* ---- frame ----------------------------------------------------------------------- */

/** Producer: returns the payload of the next slot to fill (elem_size bytes), marking it
 *  being written. Follow with arflex_frame_commit. RT safe. */
ARFLEX_API void *arflex_frame_begin(struct arflex_port *p);

/** Producer: publishes the slot from arflex_frame_begin with @length valid bytes. Returns 0
 *  or -EINVAL (length > elem_size: the frame is still published, truncated). */
ARFLEX_API int arflex_frame_commit(struct arflex_port *p, uint32_t length);

/** A frame lent to a reader. */
struct arflex_frame_view {
	const void *data;      /**< into the shared segment: valid until the producer wraps */
	uint32_t length;
	uint64_t index;        /**< 0-based frame number */
	uint64_t stamp_ns;
	uint64_t skipped;      /**< frames published since the previous view and not shown */
	const struct arflex_slot_hdr *slot_;
	uint64_t seq_;
};

/** Reader: lends the newest frame newer than the last one lent by this handle. Returns 1, 0
 *  (nothing new), -EPROTO (damaged header: nothing lent), -EINVAL. No copy. RT safe. */
ARFLEX_API int arflex_frame_acquire(struct arflex_port *p, struct arflex_frame_view *v);

/** Reader: true if the frame in @v was not overwritten while it was used; call after use and
 *  discard the results when false. */
ARFLEX_API bool arflex_frame_valid(const struct arflex_frame_view *v);

#ifdef __cplusplus
}
#endif
#endif /* ARFLEX_PORT_H */
