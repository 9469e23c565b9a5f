package org.arflex.drcr.impl.supervisor;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import com.sun.jna.LastErrorException;
import java.io.IOException;
import java.nio.file.Files;
import java.nio.file.Path;
import java.nio.file.attribute.PosixFilePermissions;
import java.util.ArrayList;
import java.util.List;
import org.arflex.drcr.impl.abi.Mailbox;
import org.arflex.drcr.impl.abi.MessageQueue;
import org.arflex.drcr.impl.abi.Posix;
import org.arflex.drcr.impl.abi.ShmSegment;
import org.junit.jupiter.api.Test;

/**
 * Issue 16 finding 6: names created by someone else before the runtime creates them. Before,
 * the O_EXCL creation failed and the component went FAILED after its restarts; now the
 * squatter's object is removed (never mapped or read) and a fresh one is created.
 */
class SquattersTest {

    private final List<String> log = new ArrayList<>();
    private final String base = "/arflex.sqt" + ProcessHandle.current().pid() + "-" + System.nanoTime();

    @Test
    void aSquattedSegmentIsRemovedNeverAdoptedAndCreatedAfresh() throws IOException {
        String name = base + ".ctl";
        Path file = Path.of("/dev/shm", name.substring(1));
        Files.write(file, new byte[] {'A', 'A', 'A', 'A', 'A', 'A', 'A', 'A'});
        Files.setPosixFilePermissions(file, PosixFilePermissions.fromString("rw-rw-rw-"));
        try (ShmSegment s = Squatters.createExclusive("probe", List.of(name), List.of(),
                () -> ShmSegment.create(name, 4096), log::add)) {
            assertEquals(0, s.getLong(0), "the squatter's bytes were adopted");
            assertEquals("rw-------", PosixFilePermissions.toString(Files.getPosixFilePermissions(file)));
            assertEquals(4096, Files.size(file));
        } finally {
            ShmSegment.unlinkQuietly(name);
        }
        assertEquals(1, log.size(), log.toString());
        assertTrue(log.get(0).contains(name) && log.get(0).contains("existed before") && log.get(0).contains("rw-rw-rw-")
                && log.get(0).contains("never adopted"), log.get(0));
    }

    /** Issue 30 finding 4: a directory at the name (shm_unlink cannot remove one) made every restart fail. */
    @Test
    void aSquattedDirectoryIsMovedAsideAndTheSegmentCreated() throws IOException {
        String name = base + ".ctl";
        Path dir = Path.of("/dev/shm", name.substring(1));
        Files.createDirectory(dir);
        Files.write(dir.resolve("keep"), new byte[] {1});
        List<Path> aside = new ArrayList<>();
        try (ShmSegment s = Squatters.createExclusive("probe", List.of(name), List.of(),
                () -> ShmSegment.create(name, 4096), log::add)) {
            assertTrue(Files.isRegularFile(dir), "the segment was created at the name");
        } finally {
            ShmSegment.unlinkQuietly(name);
            try (var ds = Files.newDirectoryStream(dir.getParent(), "squatted." + dir.getFileName() + ".*")) {
                ds.forEach(aside::add);
            }
            for (Path p : aside) {
                Files.deleteIfExists(p.resolve("keep"));
                Files.deleteIfExists(p);
            }
            Files.deleteIfExists(dir.resolve("keep"));
            Files.deleteIfExists(dir);
        }
        assertEquals(1, aside.size(), "the squatter's directory, with what it holds, kept aside: " + aside);
        assertEquals(1, log.size(), log.toString());
        assertTrue(log.get(0).contains("a directory") && log.get(0).contains("moved aside to ")
                && log.get(0).contains("never adopted"), log.get(0));
    }

    @Test
    void squattedQueuesAreRemovedAndTheMailboxCreated() throws IOException {
        String cmd = base + ".cmd";
        String rsp = base + ".rsp";
        Posix.MqAttr attr = new Posix.MqAttr();
        attr.mq_maxmsg = 1;
        attr.mq_msgsize = 8;
        int d = Posix.LIBC.mq_open(rsp, Posix.O_CREAT | Posix.O_EXCL | Posix.O_RDWR, 0666, attr);
        Posix.LIBC.mq_close(d);
        try (Mailbox mb = Squatters.createExclusive("probe", List.of(), List.of(cmd, rsp),
                () -> Mailbox.create(cmd, rsp, 42), log::add)) {
            assertEquals(rsp, mb.rspName());
        } finally {
            MessageQueue.unlinkQuietly(cmd);
            MessageQueue.unlinkQuietly(rsp);
        }
        assertEquals(1, log.size(), log.toString());
        assertTrue(log.get(0).contains("message queue " + rsp), log.get(0));
    }

    @Test
    void aNameMadeAgainAtOnceIsReportedAsSquatted() {
        IOException e = assertThrows(IOException.class, () -> Squatters.createExclusive("probe", List.of(base + ".x"),
                List.of(), () -> {
                    throw new IOException("shm_open: exists", new LastErrorException(Posix.EEXIST));
                }, log::add));
        assertTrue(e.getMessage().contains("made again by another process"), e.getMessage());
    }

    @Test
    void otherFailuresPassThroughUntouched() {
        IOException e = assertThrows(IOException.class, () -> Squatters.createExclusive("probe", List.of(base + ".y"),
                List.of(), () -> {
                    throw new IOException("shm_open: no space", new LastErrorException(28));
                }, log::add));
        assertEquals("shm_open: no space", e.getMessage());
        assertFalse(log.stream().anyMatch(l -> l.contains("removed")));
    }
}
