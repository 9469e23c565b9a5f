package org.arflex.drcr.impl.abi;

import com.sun.jna.LastErrorException;
import com.sun.jna.Pointer;
import java.io.IOException;
import java.lang.invoke.MethodHandles;
import java.lang.invoke.VarHandle;
import java.nio.ByteBuffer;
import java.nio.ByteOrder;

/**
 * A POSIX shared-memory object the manager created (O_CREAT|O_EXCL, mode 0600), mapped
 * read-write. Shared words are read and written through VarHandles on a direct buffer, which
 * gives the acquire/release semantics the C side uses (and atomicity of aligned 8-byte words).
 * {@link #close()} unmaps; {@link #unlink()} removes the name. The owner calls both on every
 * exit path.
 */
public final class ShmSegment implements AutoCloseable {

    private static final VarHandle LONGS = MethodHandles.byteBufferViewVarHandle(long[].class, ByteOrder.LITTLE_ENDIAN);
    private static final VarHandle INTS = MethodHandles.byteBufferViewVarHandle(int[].class, ByteOrder.LITTLE_ENDIAN);

    private final String name;
    private final long size;
    private Pointer base;
    private final ByteBuffer buf;
    private boolean unlinked;

    private ShmSegment(String name, long size, Pointer base) {
        this.name = name;
        this.size = size;
        this.base = base;
        this.buf = base.getByteBuffer(0, size).order(ByteOrder.LITTLE_ENDIAN);
    }

    /**
     * Creates and maps a new zero-filled object; fails if the name exists.
     *
     * @throws IOException naming the object and the errno
     */
    public static ShmSegment create(String name, long size) throws IOException {
        int fd;
        try {
            fd = Posix.LIBC.shm_open(name, Posix.O_CREAT | Posix.O_EXCL | Posix.O_RDWR, 0600);
        } catch (LastErrorException e) {
            throw new IOException("shm_open(" + name + ", O_CREAT|O_EXCL, 0600): " + Posix.describe(e), e);
        }
        try {
            Posix.LIBC.ftruncate(fd, size);
            Pointer p = Posix.LIBC.mmap(null, size, Posix.PROT_READ | Posix.PROT_WRITE, Posix.MAP_SHARED, fd, 0);
            return new ShmSegment(name, size, p);
        } catch (LastErrorException e) {
            unlinkQuietly(name);
            throw new IOException("shm " + name + " (" + size + " bytes): " + Posix.describe(e), e);
        } finally {
            try {
                Posix.LIBC.close(fd);
            } catch (LastErrorException ignored) {
                // the mapping keeps the object alive; a failed close of the fd changes nothing
            }
        }
    }

    /** Removes {@code name}; true when it existed. */
    public static boolean unlinkQuietly(String name) {
        try {
            Posix.LIBC.shm_unlink(name);
            return true;
        } catch (LastErrorException e) {
            return false;
        }
    }

    public String name() {
        return name;
    }

    public long size() {
        return size;
    }

    /** The mapping's address (null once closed); for the native heartbeat writer only. */
    synchronized Pointer address() {
        return base;
    }

    /** The mapped bytes (little endian, absolute indexing only). */
    public ByteBuffer buffer() {
        return buf;
    }

    public long getLongAcquire(int off) {
        return (long) LONGS.getAcquire(buf, off);
    }

    public void setLongRelease(int off, long v) {
        LONGS.setRelease(buf, off, v);
    }

    public int getIntAcquire(int off) {
        return (int) INTS.getAcquire(buf, off);
    }

    public void setIntRelease(int off, int v) {
        INTS.setRelease(buf, off, v);
    }

    public long getLong(int off) {
        return buf.getLong(off);
    }

    public void putLong(int off, long v) {
        buf.putLong(off, v);
    }

    public int getInt(int off) {
        return buf.getInt(off);
    }

    public void putInt(int off, int v) {
        buf.putInt(off, v);
    }

    /** Writes a NUL-terminated ASCII string into a field of {@code fieldSize} bytes. */
    public void putString(int off, int fieldSize, String s) {
        byte[] b = s.getBytes(java.nio.charset.StandardCharsets.US_ASCII);
        if (b.length >= fieldSize) {
            throw new IllegalArgumentException("'" + s + "' does not fit in " + (fieldSize - 1) + " bytes");
        }
        for (int i = 0; i < fieldSize; i++) {
            buf.put(off + i, i < b.length ? b[i] : 0);
        }
    }

    /** Reads a NUL-terminated ASCII string from a field. */
    public String getString(int off, int fieldSize) {
        StringBuilder sb = new StringBuilder();
        for (int i = 0; i < fieldSize; i++) {
            byte c = buf.get(off + i);
            if (c == 0) {
                break;
            }
            sb.append((char) c);
        }
        return sb.toString();
    }

    /** Removes the name (the mapping stays valid until {@link #close()}). Idempotent. */
    public synchronized void unlink() {
        if (!unlinked) {
            unlinked = true;
            unlinkQuietly(name);
        }
    }

    /** Unmaps. Idempotent. Callers must not touch {@link #buffer()} afterwards. */
    @Override
    public synchronized void close() {
        if (base != null) {
            try {
                Posix.LIBC.munmap(base, size);
            } catch (LastErrorException ignored) {
                // nothing left to do: the address range is ours and stays reserved
            }
            base = null;
        }
    }
}
