package org.arflex.drcr.impl.supervisor;

import com.sun.jna.LastErrorException;
import java.io.IOException;
import java.nio.file.Files;
import java.nio.file.LinkOption;
import java.nio.file.Path;
import java.nio.file.StandardCopyOption;
import java.nio.file.attribute.PosixFileAttributes;
import java.nio.file.attribute.PosixFilePermissions;
import java.security.SecureRandom;
import java.util.List;
import java.util.function.Consumer;
import org.arflex.drcr.impl.abi.MessageQueue;
import org.arflex.drcr.impl.abi.ShmSegment;

/**
 * A name the runtime is about to create that exists already (issue 16 finding 6): /dev/shm and
 * /dev/mqueue are writable by every user, so anyone who has seen a runtime id can create the
 * names of the next spawn first. Every object is created O_CREAT|O_EXCL, so such an object is
 * never adopted; before this class it made the spawn fail, three times, and the component
 * FAILED (denial of service). Now the creation that fails with EEXIST removes the names it
 * wanted (saying who owned them and with which mode), then tries once more; a name made again
 * in between is reported as such. Nothing of the squatter's is read or mapped.
 */
final class Squatters {

    /** A creation that may fail with EEXIST. */
    interface Create<T> {
        T create() throws IOException;
    }

    private static final SecureRandom RANDOM = new SecureRandom();

    private Squatters() {
    }

    /**
     * Runs {@code create}; on EEXIST removes {@code shm} and {@code mq} names that exist, logs
     * each, and runs it once more.
     */
    static <T> T createExclusive(String inst, List<String> shm, List<String> mq, Create<T> create,
                                 Consumer<String> log) throws IOException {
        try {
            return create.create();
        } catch (IOException e) {
            if (!exists(e)) {
                throw e;
            }
        }
        List<String> kept = new java.util.ArrayList<>();
        for (String n : shm) {
            Path path = Path.of("/dev/shm", n.substring(1));
            String who = owner(path);
            if (who != null && !ShmSegment.unlinkQuietly(n)) {
                String aside = moveAside(path);
                if (aside == null) {
                    kept.add(n + " (" + who + ")");
                } else {
                    log.accept("arflex: " + inst + ": " + path + " existed before this runtime created it (" + who
                            + "), a directory shm_unlink cannot remove: " + aside + ", never adopted");
                }
            } else if (who != null) {
                log.accept("arflex: " + inst + ": shared memory " + n + " existed before this runtime created it ("
                        + who + "): removed, never adopted");
            }
        }
        for (String n : mq) {
            String who = owner(Path.of("/dev/mqueue", n.substring(1)));
            if (MessageQueue.unlinkQuietly(n)) {
                log.accept("arflex: " + inst + ": message queue " + n + " existed before this runtime created it ("
                        + (who != null ? who : "owner unknown: /dev/mqueue not mounted") + "): removed, never adopted");
            }
        }
        if (!kept.isEmpty()) {
            throw new IOException(inst + ": " + kept + " existed before this runtime created it and cannot be removed by "
                    + "it (not its own): never adopted; remove it as its owner or root");
        }
        try {
            return create.create();
        } catch (IOException e) {
            if (exists(e)) {
                throw new IOException(inst + ": a name it creates was made again by another process as soon as it was "
                        + "removed (someone on this machine squats " + shm + " " + mq + "): " + e.getMessage(), e);
            }
            throw e;
        }
    }

    /**
     * Frees a name shm_unlink cannot remove (a directory, issue 30 finding 4): an empty one is
     * removed (rmdir), any other is renamed aside within the folder (rename neither follows nor
     * opens anything; what it holds stays its owner's). Null when neither worked (not root).
     */
    static String moveAside(Path p) {
        try {
            Files.delete(p);
            return "removed";
        } catch (IOException e) {
            // not empty, or not ours to remove
        }
        Path to = p.resolveSibling("squatted." + p.getFileName() + "." + Long.toHexString(RANDOM.nextLong()));
        try {
            Files.move(p, to, StandardCopyOption.ATOMIC_MOVE);
            return "moved aside to " + to;
        } catch (IOException e) {
            return null;
        }
    }

    /** Whether the failure is EEXIST. */
    static boolean exists(IOException e) {
        return e.getCause() instanceof LastErrorException le && le.getErrorCode() == org.arflex.drcr.impl.abi.Posix.EEXIST;
    }

    /** "owner uid N, mode rw-rw-rw-" of a path, null when it does not exist or cannot be read. */
    private static String owner(Path p) {
        try {
            PosixFileAttributes a = Files.readAttributes(p, PosixFileAttributes.class, LinkOption.NOFOLLOW_LINKS);
            Object uid = Files.getAttribute(p, "unix:uid", LinkOption.NOFOLLOW_LINKS);
            return "owner " + a.owner().getName() + " (uid " + uid + "), mode " + PosixFilePermissions.toString(a.permissions());
        } catch (IOException | UnsupportedOperationException e) {
            return null;
        }
    }
}
