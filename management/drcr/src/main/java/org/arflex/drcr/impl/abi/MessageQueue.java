package org.arflex.drcr.impl.abi;

import com.sun.jna.LastErrorException;
import java.io.IOException;
import java.util.Arrays;
import java.util.Optional;

/**
 * A POSIX message queue the manager created (O_CREAT|O_EXCL, mode 0600). This machine allows
 * at most 10 messages of at most 8 KiB; commands only, data goes through shared memory.
 */
public final class MessageQueue implements AutoCloseable {

    private final String name;
    private final int msgSize;
    private int mqd;
    private boolean unlinked;

    private MessageQueue(String name, int mqd, int msgSize) {
        this.name = name;
        this.mqd = mqd;
        this.msgSize = msgSize;
    }

    /** Creates a new queue; fails if the name exists. */
    public static MessageQueue create(String name, int maxMsg, int msgSize) throws IOException {
        Posix.MqAttr attr = new Posix.MqAttr();
        attr.mq_maxmsg = maxMsg;
        attr.mq_msgsize = msgSize;
        try {
            int mqd = Posix.LIBC.mq_open(name, Posix.O_CREAT | Posix.O_EXCL | Posix.O_RDWR, 0600, attr);
            return new MessageQueue(name, mqd, msgSize);
        } catch (LastErrorException e) {
            throw new IOException("mq_open(" + name + ", O_CREAT|O_EXCL, 0600, maxmsg " + maxMsg + ", msgsize "
                    + msgSize + "): " + Posix.describe(e), e);
        }
    }

    /** Removes {@code name}; true when it existed. */
    public static boolean unlinkQuietly(String name) {
        try {
            Posix.LIBC.mq_unlink(name);
            return true;
        } catch (LastErrorException e) {
            return false;
        }
    }

    public String name() {
        return name;
    }

    /**
     * Sends one message, waiting at most {@code timeoutMs} for room.
     *
     * @throws IOException on timeout or error, naming the queue
     */
    public void send(byte[] msg, long timeoutMs) throws IOException {
        int d = mqd;
        if (d < 0) {
            throw new IOException("mq " + name + " is closed");
        }
        try {
            Posix.LIBC.mq_timedsend(d, msg, msg.length, 0, Posix.Timespec.of(deadline(timeoutMs)));
        } catch (LastErrorException e) {
            throw new IOException("mq_timedsend(" + name + "): " + Posix.describe(e), e);
        }
    }

    /** Receives one message, or empty after {@code timeoutMs}. */
    public Optional<byte[]> receive(long timeoutMs) throws IOException {
        int d = mqd;
        if (d < 0) {
            throw new IOException("mq " + name + " is closed");
        }
        byte[] b = new byte[msgSize];
        try {
            long n = Posix.LIBC.mq_timedreceive(d, b, b.length, null, Posix.Timespec.of(deadline(timeoutMs)));
            return Optional.of(Arrays.copyOf(b, (int) n));
        } catch (LastErrorException e) {
            if (e.getErrorCode() == Posix.ETIMEDOUT) {
                return Optional.empty();
            }
            throw new IOException("mq_timedreceive(" + name + "): " + Posix.describe(e), e);
        }
    }

    private static long deadline(long timeoutMs) {
        // mq_timed* take an absolute CLOCK_REALTIME deadline.
        return System.currentTimeMillis() * 1_000_000L + Math.max(0, timeoutMs) * 1_000_000L;
    }

    /** Removes the name. Idempotent. */
    public synchronized void unlink() {
        if (!unlinked) {
            unlinked = true;
            unlinkQuietly(name);
        }
    }

    /** True when a queue of that name exists (works without /dev/mqueue mounted). */
    public static boolean exists(String name) {
        try {
            int d = Posix.LIBC.mq_open(name, Posix.O_RDONLY | Posix.O_NONBLOCK);
            Posix.LIBC.mq_close(d);
            return true;
        } catch (LastErrorException e) {
            return e.getErrorCode() != Posix.ENOENT;
        }
    }

    /** Removes the name and closes the descriptor (the manager owns the queue). Idempotent. */
    @Override
    public synchronized void close() {
        unlink();
        if (mqd >= 0) {
            try {
                Posix.LIBC.mq_close(mqd);
            } catch (LastErrorException ignored) {
                // the descriptor is gone either way
            }
            mqd = -1;
        }
    }
}
