package org.arflex.drcr.impl;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertTimeoutPreemptively;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.nio.ByteBuffer;
import java.nio.ByteOrder;
import java.nio.file.Files;
import java.nio.file.Path;
import java.nio.file.attribute.UserPrincipal;
import java.time.Duration;
import java.util.ArrayList;
import java.util.Comparator;
import java.util.List;
import java.util.concurrent.TimeUnit;
import java.util.stream.Stream;
import org.arflex.drcr.impl.abi.ControlBlock;
import org.arflex.drcr.impl.supervisor.HalfRecords;
import org.junit.jupiter.api.AfterEach;
import org.junit.jupiter.api.Test;

/**
 * Issue 30 findings 2 and 3 (D79) on a folder standing in for /dev/shm: what anyone can put
 * under a stale runtime's names (a FIFO, a directory, a symlink, a file of another user's that
 * names a pid) neither blocks the sweep nor gets a process signalled; only the runtime's own
 * record of a half it spawned does.
 */
class SweeperDoorsTest {

    /** A default runtime id whose JVM is not running (pid beyond pid_max). */
    private static final String STALE = "rt99999999-0000000000";
    private static final String OWN = "own" + ProcessHandle.current().pid();

    private final Path root;
    private final Path shm;
    private final HalfRecords records;
    private final List<String> log = new ArrayList<>();
    private final List<Integer> killed = new ArrayList<>();
    private final List<Process> started = new ArrayList<>();

    SweeperDoorsTest() throws IOException {
        root = Files.createTempDirectory("sweeper-doors");
        shm = Files.createDirectory(root.resolve("shm"));
        records = new HalfRecords(root.resolve("records"), log::add);
    }

    @AfterEach
    void cleanUp() throws IOException {
        started.forEach(Process::destroyForcibly);
        try (Stream<Path> s = Files.walk(root)) {
            for (Path p : s.sorted(Comparator.reverseOrder()).toList()) {
                Files.delete(p);
            }
        }
    }

    private List<String> sweep(String own) {
        return new Sweeper(shm, root.resolve("no-mqueue"), records, pid -> killed.add(pid), log::add).sweep(own);
    }

    /** A live process of ours whose command line holds {@code --runtime rid }, child of this JVM (a java). */
    private long liveHalfLookalike(String rid) throws IOException {
        Process p = new ProcessBuilder("sh", "-c", "sleep 60; :", "x", "--runtime", rid, "--instance", "x").start();
        started.add(p);
        return p.pid();
    }

    private static byte[] ctl(long pid) {
        ByteBuffer b = ByteBuffer.allocate(64).order(ByteOrder.LITTLE_ENDIAN);
        b.putLong(ControlBlock.OFF_MAGIC, ControlBlock.MAGIC).putInt(ControlBlock.OFF_PID, (int) pid);
        return b.array();
    }

    private static void mkfifo(Path p) throws IOException, InterruptedException {
        assertEquals(0, new ProcessBuilder("mkfifo", p.toString()).inheritIO().start().waitFor());
    }

    private static UserPrincipal nobody(Path p) throws IOException {
        return p.getFileSystem().getUserPrincipalLookupService().lookupPrincipalByName("nobody");
    }

    /** Finding 2: the sweep opened a FIFO for reading and blocked, at start-up and at stop. */
    @Test
    void aFifoIsRemovedNeverOpened() throws Exception {
        Path stale = shm.resolve("arflex." + STALE + ".x.ctl");
        Path own = shm.resolve("arflex." + OWN + ".x.ctl");
        mkfifo(stale);
        mkfifo(own);
        List<String> removed = assertTimeoutPreemptively(Duration.ofSeconds(10), () -> sweep(OWN),
                "the sweep blocked on a FIFO");
        assertFalse(Files.exists(stale) || Files.exists(own), "both FIFOs removed: " + removed);
        assertTrue(log.stream().anyMatch(l -> l.contains(stale.toString()) && l.contains("a FIFO")), log.toString());
        assertTrue(log.stream().anyMatch(l -> l.contains(own.toString()) && l.contains("a FIFO") && l.contains("not read")),
                log.toString());
    }

    @Test
    void aDirectoryIsLeftAndSaidSo() {
        Path d = shm.resolve("arflex." + STALE + ".x.ctl");
        assertTimeoutPreemptively(Duration.ofSeconds(10), () -> {
            Files.createDirectory(d);
            Files.createDirectory(shm.resolve("arflex." + OWN + ".x.ctl"));
            sweep(OWN);
        });
        assertTrue(Files.isDirectory(d));
        assertTrue(log.stream().anyMatch(l -> l.contains("left " + d) && l.contains("a directory")), log.toString());
    }

    /** A symlink is removed, its target neither read nor touched, the pid in the target not signalled. */
    @Test
    void aSymlinkIsRemovedItsTargetUntouched() throws Exception {
        long pid = liveHalfLookalike(STALE);
        Path target = Files.write(root.resolve("target"), ctl(pid));
        Path link = Files.createSymbolicLink(shm.resolve("arflex." + STALE + ".x.ctl"), target);
        Path ownLink = Files.createSymbolicLink(shm.resolve("arflex." + OWN + ".x.ctl"), target);
        sweep(OWN);
        assertFalse(Files.exists(link, java.nio.file.LinkOption.NOFOLLOW_LINKS));
        assertFalse(Files.exists(ownLink, java.nio.file.LinkOption.NOFOLLOW_LINKS));
        assertTrue(Files.isRegularFile(target), "the target stays");
        assertEquals(List.of(), killed);
        assertTrue(log.stream().anyMatch(l -> l.contains("a symlink")), log.toString());
    }

    /**
     * Finding 3: a control block of another user's naming a live process with {@code --runtime
     * <rid>} under a java parent made the DRCR refuse to start (our id) or sent SIGKILL (a
     * stale id).
     */
    @Test
    void aForeignControlBlockNamesNoOneToKillAndNoIdInUse() throws Exception {
        for (String rid : new String[] {STALE, OWN}) {
            Path f = Files.write(shm.resolve("arflex." + rid + ".x.ctl"), ctl(liveHalfLookalike(rid)));
            Files.setOwner(f, nobody(f));
        }
        List<String> removed = sweep(OWN);
        assertEquals(List.of(), killed, "no process named by a file in /dev/shm is signalled");
        assertEquals(2, removed.size(), removed.toString());
        assertTrue(log.stream().anyMatch(l -> l.contains("a file owned by uid 65534")), log.toString());
    }

    /** Even our own user's control block of a stale id gets no one killed: only records do. */
    @Test
    void onlyARecordedHalfIsKilledAndOnlyWhileItIsThatProcess() throws Exception {
        long unrecorded = liveHalfLookalike(STALE);
        Files.write(shm.resolve("arflex." + STALE + ".a.ctl"), ctl(unrecorded));
        long recorded = liveHalfLookalike(STALE);
        records.spawned(STALE, "b", recorded);
        long reused = liveHalfLookalike(STALE);
        records.spawned(STALE, "c", reused);
        // the pid "c" was recorded for has been reused since: another start time
        Path c = records.dir().resolve(STALE + ".c." + reused);
        Files.writeString(c, reused + " " + (HalfRecords.startTime(reused) - 1) + "\n");
        sweep(OWN);
        assertEquals(List.of((int) recorded), killed);
        assertTrue(log.stream().anyMatch(l -> l.contains("killed orphaned RT half b pid " + recorded)), log.toString());
        assertEquals(List.of(), records.all(), "records of a dead runtime are removed once swept");
        for (Process p : started) {
            if (p.pid() != recorded) {
                assertFalse(p.waitFor(0, TimeUnit.MILLISECONDS), "pid " + p.pid() + " left alone");
            }
        }
    }
}
