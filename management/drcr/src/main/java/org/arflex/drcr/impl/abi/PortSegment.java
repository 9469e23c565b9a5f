package org.arflex.drcr.impl.abi;

import java.io.IOException;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.NoSuchFileException;
import java.nio.file.Path;

/**
 * An output port segment {@code /arflex.<rid>.<inst>.out.<port>}: Java side of struct
 * arflex_port_hdr in rt-core/include/arflex/port.h. The manager creates and formats it (as
 * arflex_port_create does) before the producer starts, and removes it when the producer is
 * destroyed; it survives restarts of its producer, so consumers keep their mapping. The offsets
 * below come from {@link Layout}, generated from the header (DECISIONS.md D22).
 */
public final class PortSegment implements AutoCloseable {

    public static final long MAGIC = Layout.PORT_MAGIC; // "ARFLXPRT"
    public static final int HDR_SIZE = Layout.PORT_HDR_SIZE;
    /** Port segment layout version (ABI.md §4; 2.0 since DECISIONS.md D30), not the control block's. */
    public static final int ABI_MAJOR = Layout.PORT_ABI_MAJOR;
    public static final int ABI_MINOR = Layout.PORT_ABI_MINOR;
    /** Slot header bytes; the payload follows right after it (ABI 2.0). */
    public static final int SLOT_HDR_SIZE = Layout.SLOT_HDR_SIZE;
    public static final int SLOT_ALIGN = Layout.SLOT_ALIGN;
    public static final int TYPE_NAME_SIZE = Layout.TYPE_NAME_SIZE;
    public static final int OFF_MAGIC = Layout.OFF_PORT_HDR_MAGIC;
    public static final int OFF_ABI_MAJOR = Layout.OFF_PORT_HDR_ABI_MAJOR;
    public static final int OFF_ABI_MINOR = Layout.OFF_PORT_HDR_ABI_MINOR;
    public static final int OFF_HEADER_SIZE = Layout.OFF_PORT_HDR_HEADER_SIZE;
    public static final int OFF_SIZE = Layout.OFF_PORT_HDR_SIZE;
    public static final int OFF_METHOD = Layout.OFF_PORT_HDR_METHOD;
    public static final int OFF_ELEM_SIZE = Layout.OFF_PORT_HDR_ELEM_SIZE;
    public static final int OFF_DEPTH = Layout.OFF_PORT_HDR_DEPTH;
    public static final int OFF_OVERFLOW = Layout.OFF_PORT_HDR_OVERFLOW;
    public static final int OFF_SLOT_STRIDE = Layout.OFF_PORT_HDR_SLOT_STRIDE;
    public static final int OFF_TYPE_MAJOR = Layout.OFF_PORT_HDR_TYPE_MAJOR;
    public static final int OFF_TYPE_MINOR = Layout.OFF_PORT_HDR_TYPE_MINOR;
    public static final int OFF_TYPE_HASH = Layout.OFF_PORT_HDR_TYPE_HASH;
    public static final int OFF_TYPE_NAME = Layout.OFF_PORT_HDR_TYPE_NAME;
    public static final int OFF_HEAD = Layout.OFF_PORT_HDR_HEAD;
    public static final int OFF_WRITTEN = Layout.OFF_PORT_HDR_WRITTEN;
    public static final int OFF_WRITER_PID = Layout.OFF_PORT_HDR_WRITER_PID;
    public static final int OFF_TAIL = Layout.OFF_PORT_HDR_TAIL;
    public static final int METHOD_STATE = Layout.PORT_STATE;
    public static final int METHOD_STREAM = Layout.PORT_STREAM;
    public static final int METHOD_FRAME = Layout.PORT_FRAME;
    public static final int OVERFLOW_NONE = Layout.OVERFLOW_NONE;
    public static final int OVERFLOW_DROP_OLDEST = Layout.OVERFLOW_DROP_OLDEST;
    public static final int OVERFLOW_DROP_NEWEST = Layout.OVERFLOW_DROP_NEWEST;
    public static final int MAX_DEPTH = Layout.PORT_MAX_DEPTH;
    public static final long MAX_ELEM = Layout.PORT_MAX_ELEM;

    private final ShmSegment shm;
    private final int method;
    private final int depth;
    private final int stride;

    private PortSegment(ShmSegment shm, int method, int depth, int stride) {
        this.shm = shm;
        this.method = method;
        this.depth = depth;
        this.stride = stride;
    }

    /** FNV-1a 64 over the bytes of the type name, as arflex_port_type_hash. */
    public static long typeHash(String name) {
        long h = 0xcbf29ce484222325L;
        for (byte b : name.getBytes(StandardCharsets.UTF_8)) {
            h ^= b & 0xff;
            h *= 0x100000001b3L;
        }
        return h;
    }

    /** Stride of one slot: slot header plus payload, rounded up to 64 (ABI.md §4, one rule for every method). */
    public static int stride(int elemSize) {
        return (SLOT_HDR_SIZE + elemSize + SLOT_ALIGN - 1) & -SLOT_ALIGN;
    }

    /** Segment size: header plus depth slots, rounded up to 4096, as arflex_port_segment_size. */
    public static long segmentSize(int method, int elemSize, int depth) {
        int d = method == METHOD_STATE ? 1 : depth;
        long s = HDR_SIZE + (long) d * stride(elemSize);
        return (s + 4095) & ~4095L;
    }

    /** Creates and formats an output segment. */
    public static PortSegment create(String name, int method, String typeName, int typeMajor, int typeMinor,
                                     int elemSize, int depth, int overflow) throws IOException {
        if (elemSize <= 0 || elemSize > MAX_ELEM) {
            throw new IOException("port " + name + ": element size " + elemSize + " not in 1.." + MAX_ELEM);
        }
        int d = method == METHOD_STATE ? 1 : depth;
        if (d < 1 || d > MAX_DEPTH) {
            throw new IOException("port " + name + ": depth " + depth + " not in 1.." + MAX_DEPTH);
        }
        if (typeName.getBytes(StandardCharsets.UTF_8).length >= TYPE_NAME_SIZE) {
            throw new IOException("port " + name + ": type name '" + typeName + "' longer than 63 bytes");
        }
        long size = segmentSize(method, elemSize, d);
        ShmSegment s = ShmSegment.create(name, size);
        s.buffer().putShort(OFF_ABI_MAJOR, (short) ABI_MAJOR);
        s.buffer().putShort(OFF_ABI_MINOR, (short) ABI_MINOR);
        s.putInt(OFF_HEADER_SIZE, HDR_SIZE);
        s.putLong(OFF_SIZE, size);
        s.putInt(OFF_METHOD, method);
        s.putInt(OFF_ELEM_SIZE, elemSize);
        s.putInt(OFF_DEPTH, d);
        s.putInt(OFF_OVERFLOW, method == METHOD_STREAM ? overflow : OVERFLOW_NONE);
        s.putInt(OFF_SLOT_STRIDE, stride(elemSize));
        s.buffer().putShort(OFF_TYPE_MAJOR, (short) typeMajor);
        s.buffer().putShort(OFF_TYPE_MINOR, (short) typeMinor);
        s.putLong(OFF_TYPE_HASH, typeHash(typeName));
        s.putString(OFF_TYPE_NAME, TYPE_NAME_SIZE, typeName);
        s.setLongRelease(OFF_MAGIC, MAGIC); // ABI.md 6.1: header magic last
        return new PortSegment(s, method, d, stride(elemSize));
    }

    /**
     * Why this segment is no longer what {@link #create} made, or null when it is intact: the
     * object in /dev/shm is gone or has another size (checked first: touching the mapping of a
     * truncated object would fault), or the header's magic, method, depth or slot stride was
     * overwritten (what rt-core's readers re-check, ABI.md §4).
     */
    public String damage() {
        long now;
        try {
            now = Files.size(Path.of("/dev/shm", shm.name()));
        } catch (NoSuchFileException e) {
            return "removed from /dev/shm";
        } catch (IOException e) {
            return "cannot stat: " + e.getMessage();
        }
        if (now != shm.size()) {
            return "size " + now + " B, created with " + shm.size() + " B";
        }
        long magic = shm.getLongAcquire(OFF_MAGIC);
        if (magic != MAGIC) {
            return String.format("magic 0x%016x, not 0x%016x", magic, MAGIC);
        }
        if (shm.getInt(OFF_METHOD) != method || shm.getInt(OFF_DEPTH) != depth
                || shm.getInt(OFF_SLOT_STRIDE) != stride) {
            return "geometry overwritten: method " + shm.getInt(OFF_METHOD) + " depth " + shm.getInt(OFF_DEPTH)
                    + " stride " + shm.getInt(OFF_SLOT_STRIDE) + ", created " + method + "/" + depth + "/" + stride;
        }
        return null;
    }

    public String name() {
        return shm.name();
    }

    /** Elements published by the producer. */
    public long head() {
        return shm.getLongAcquire(OFF_HEAD);
    }

    /** Write attempts by the producer. */
    public long written() {
        return shm.getLongAcquire(OFF_WRITTEN);
    }

    /** The mapped segment, for monitoring reads. */
    public ShmSegment segment() {
        return shm;
    }

    /** Unmaps and removes the segment. */
    @Override
    public void close() {
        shm.unlink();
        shm.close();
    }
}
