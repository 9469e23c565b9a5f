package org.arflex.drcr.impl.abi;

import com.sun.jna.LastErrorException;
import com.sun.jna.Pointer;
import java.io.IOException;
import java.lang.invoke.MethodHandles;
import java.lang.invoke.VarHandle;
import java.nio.ByteBuffer;
import java.nio.ByteOrder;

/**
 * Reads the newest value of an output port segment the way a monitor may (ABI.md §4): the
 * segment is opened {@code O_RDONLY} and mapped {@code PROT_READ} for the one read and unmapped
 * again, the slot is copied under its seqlock, and nothing in the segment is written (a stream
 * is peeked, never consumed). The object's real size is checked before any slot is touched, so
 * a segment being created or of another shape is refused, never read past its end.
 */
public final class PortReader {

    private static final VarHandle LONGS = MethodHandles.byteBufferViewVarHandle(long[].class, ByteOrder.LITTLE_ENDIAN);
    /** Seqlock attempts per read, as the C reader (ARFLEX_STATE_READ_RETRIES). */
    static final int ATTEMPTS = Layout.STATE_READ_RETRIES;

    /** A copied value: element index, producer stamp, payload bytes, and the header's head. */
    public record Value(long index, long stampNs, byte[] payload, long published) {
    }

    private PortReader() {
    }

    /**
     * Copies the newest value of the segment {@code name}.
     *
     * @param typeName type the segment must carry (checked against its type hash)
     * @param bytes    payload bytes wanted (at most the segment's element size)
     * @return the value, or a value with index -1 and no payload when nothing was published yet
     *         or every attempt met a write in progress
     * @throws IOException naming the segment and what is wrong with it
     */
    public static Value readNewest(String name, String typeName, int bytes) throws IOException {
        int fd;
        try {
            fd = Posix.LIBC.shm_open(name, Posix.O_RDONLY, 0);
        } catch (LastErrorException e) {
            throw new IOException("port segment " + name + ": " + Posix.describe(e), e);
        }
        long size;
        Pointer base;
        try {
            size = Posix.LIBC.lseek(fd, 0, Posix.SEEK_END);
            if (size < PortSegment.HDR_SIZE) {
                throw new IOException("port segment " + name + ": " + size + " bytes, not yet formatted");
            }
            base = Posix.LIBC.mmap(null, size, Posix.PROT_READ, Posix.MAP_SHARED, fd, 0);
        } catch (LastErrorException e) {
            throw new IOException("port segment " + name + ": " + Posix.describe(e), e);
        } finally {
            try {
                Posix.LIBC.close(fd);
            } catch (LastErrorException ignored) {
                // the mapping (if any) does not need the descriptor
            }
        }
        try {
            ByteBuffer b = base.getByteBuffer(0, size).asReadOnlyBuffer().order(ByteOrder.LITTLE_ENDIAN);
            return read(b, size, name, typeName, bytes);
        } finally {
            try {
                Posix.LIBC.munmap(base, size);
            } catch (LastErrorException ignored) {
                // the range is ours; nothing else to do
            }
        }
    }

    /** The protocol on a mapped segment (package-private for tests). */
    static Value read(ByteBuffer b, long size, String name, String typeName, int bytes) throws IOException {
        if ((long) LONGS.getAcquire(b, PortSegment.OFF_MAGIC) != PortSegment.MAGIC) {
            throw new IOException("port segment " + name + ": no port header (magic) yet");
        }
        int major = Short.toUnsignedInt(b.getShort(PortSegment.OFF_ABI_MAJOR));
        if (major != PortSegment.ABI_MAJOR) {
            throw new IOException("port segment " + name + ": port ABI " + major + "."
                    + Short.toUnsignedInt(b.getShort(PortSegment.OFF_ABI_MINOR)) + ", this reader reads "
                    + PortSegment.ABI_MAJOR + ".x only (another slot layout: rt-core/docs/ABI.md §4)");
        }
        long hash = b.getLong(PortSegment.OFF_TYPE_HASH);
        if (hash != PortSegment.typeHash(typeName)) {
            throw new IOException("port segment " + name + ": carries type hash " + Long.toHexString(hash)
                    + ", not " + typeName);
        }
        int method = b.getInt(PortSegment.OFF_METHOD);
        int elem = b.getInt(PortSegment.OFF_ELEM_SIZE);
        int depth = b.getInt(PortSegment.OFF_DEPTH);
        int stride = b.getInt(PortSegment.OFF_SLOT_STRIDE);
        if (elem < bytes || depth < 1 || depth > PortSegment.MAX_DEPTH || stride < PortSegment.SLOT_HDR_SIZE + elem
                || PortSegment.HDR_SIZE + (long) depth * stride > size) {
            throw new IOException("port segment " + name + ": inconsistent header (elem " + elem + ", depth " + depth
                    + ", stride " + stride + ", size " + size + ", wanted " + bytes + " bytes)");
        }
        byte[] out = new byte[bytes];
        for (int attempt = 0; attempt < ATTEMPTS; attempt++) {
            long head = (long) LONGS.getAcquire(b, PortSegment.OFF_HEAD);
            int slot;
            long expect;
            if (method == PortSegment.METHOD_STATE) {
                slot = 0;
                expect = -1; // any even, non-zero seq
            } else {
                if (head == 0) {
                    return new Value(-1, 0, null, 0);
                }
                long i = head - 1;
                slot = (int) Long.remainderUnsigned(i, depth);
                expect = 2 * i + 2;
            }
            int at = PortSegment.HDR_SIZE + slot * stride;
            long s1 = (long) LONGS.getAcquire(b, at);
            if (s1 == 0 && method == PortSegment.METHOD_STATE) {
                return new Value(-1, 0, null, head);
            }
            if ((s1 & 1) != 0 || (expect >= 0 && s1 != expect)) {
                Thread.onSpinWait();
                continue;
            }
            long stamp = b.getLong(at + Layout.OFF_SLOT_HDR_STAMP_NS);
            b.get(at + PortSegment.SLOT_HDR_SIZE, out, 0, bytes);
            VarHandle.acquireFence();
            long s2 = (long) LONGS.getAcquire(b, at);
            if (s1 == s2) {
                return new Value(s1 / 2 - 1, stamp, out, head);
            }
            Thread.onSpinWait();
        }
        return new Value(-1, 0, null, (long) LONGS.getAcquire(b, PortSegment.OFF_HEAD));
    }
}
