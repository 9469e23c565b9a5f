package org.arflex.drcr.impl.abi;

import com.sun.jna.LastErrorException;
import java.io.IOException;
import java.nio.ByteBuffer;
import java.nio.ByteOrder;
import java.nio.file.Files;
import java.nio.file.LinkOption;
import java.nio.file.Path;
import java.nio.file.attribute.PosixFileAttributes;
import java.nio.file.attribute.PosixFilePermissions;
import java.util.Arrays;

/**
 * A name in a world-writable folder (/dev/shm) is only read when it is a regular file of this
 * process's user (issue 30 findings 2 and 3, D79): anyone can put a FIFO there (an open without
 * O_NONBLOCK blocks until a writer comes), a symlink to a file of root's, a directory, or a
 * file whose bytes name any pid. {@link #describe} says what a name is without opening it;
 * {@link #read} opens it with O_NOFOLLOW | O_NONBLOCK | O_NOCTTY and checks the open file with
 * fstat (type and owner) before it reads a byte.
 */
public final class OwnFile {

    private static final int S_IFMT = 0170000;
    private static final int S_IFREG = 0100000;
    private static final int STAT_SIZE = 144;
    private static final int OFF_MODE = 24;
    private static final int OFF_UID = 28;

    private OwnFile() {
    }

    /** This process's effective uid. */
    public static int euid() {
        return Posix.LIBC.geteuid();
    }

    /**
     * What {@code p} is, without following a symlink or opening it: null when it is a regular
     * file of this process's user, else e.g. "a FIFO owned by uid 1001, mode rw-r--r--".
     *
     * @throws IOException when it cannot be looked at (gone, say)
     */
    public static String foreign(Path p) throws IOException {
        PosixFileAttributes a = Files.readAttributes(p, PosixFileAttributes.class, LinkOption.NOFOLLOW_LINKS);
        int uid = (Integer) Files.getAttribute(p, "unix:uid", LinkOption.NOFOLLOW_LINKS);
        if (a.isRegularFile() && uid == euid()) {
            return null;
        }
        String kind = a.isRegularFile() ? "a file" : a.isDirectory() ? "a directory" : a.isSymbolicLink() ? "a symlink"
                : kindOf((Integer) Files.getAttribute(p, "unix:mode", LinkOption.NOFOLLOW_LINKS));
        return kind + " owned by uid " + uid + ", mode " + PosixFilePermissions.toString(a.permissions());
    }

    private static String kindOf(int mode) {
        return switch (mode & S_IFMT) {
            case 0010000 -> "a FIFO";
            case 0020000 -> "a character device";
            case 0060000 -> "a block device";
            case 0140000 -> "a socket";
            default -> "a special file (mode " + Integer.toOctalString(mode) + ")";
        };
    }

    /**
     * Reads at most {@code n} bytes from the start of {@code p}, a regular file of this user's.
     *
     * @throws IOException naming the path and what it is when it is anything else (never blocks)
     */
    public static byte[] read(Path p, int n) throws IOException {
        int fd;
        try {
            fd = Posix.LIBC.open(p.toString(), Posix.O_RDONLY | Posix.O_NOFOLLOW | Posix.O_NONBLOCK | Posix.O_NOCTTY
                    | Posix.O_CLOEXEC);
        } catch (LastErrorException e) {
            throw new IOException("open(" + p + ", O_NOFOLLOW|O_NONBLOCK): " + Posix.describe(e)
                    + (e.getErrorCode() == 40 ? " (a symlink: never followed)" : ""), e);
        }
        try {
            byte[] st = new byte[STAT_SIZE];
            Posix.LIBC.fstat(fd, st);
            ByteBuffer b = ByteBuffer.wrap(st).order(ByteOrder.LITTLE_ENDIAN);
            int mode = b.getInt(OFF_MODE);
            int uid = b.getInt(OFF_UID);
            if ((mode & S_IFMT) != S_IFREG || uid != euid()) {
                throw new IOException(p + " is " + ((mode & S_IFMT) == S_IFREG ? "a file" : kindOf(mode))
                        + " owned by uid " + uid + ", not a regular file of this runtime's user (uid " + euid() + "): not read");
            }
            byte[] buf = new byte[n];
            long got = Posix.LIBC.read(fd, buf, n);
            return Arrays.copyOf(buf, (int) Math.max(0, got));
        } catch (LastErrorException e) {
            throw new IOException(p + ": " + Posix.describe(e), e);
        } finally {
            try {
                Posix.LIBC.close(fd);
            } catch (LastErrorException ignored) {
                // the descriptor is released either way
            }
        }
    }
}
