package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.nio.ByteBuffer;
import java.nio.file.DirectoryStream;
import java.nio.file.Files;
import java.nio.file.LinkOption;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.Locale;
import java.util.Set;
import java.util.TreeSet;
import org.junit.jupiter.api.Test;

/**
 * The journals of teach halves that are gone do not accumulate (docs/DECISIONS.md D63), through
 * the real runtime: teach records a hand-guided path (its recording in its journal,
 * {@code <runtime>/data/teach-rec-<pid>-<nonce>.bin}, D57); its RT half is killed with SIGKILL;
 * the DRCR restarts it; the restarted half, once it runs, removes the killed half's journal, and
 * the data folder holds the live half's journal only. A symlink (to a file outside the folder)
 * and a file of another uid, both named like the journal of a half that is gone, are neither
 * followed nor removed: the new half's log names each.
 */
class TeachJournalIT {

    static final long T = CellRig.T;

    /** A pid no process has now: one of a process that ran and was reaped. */
    static long pidThatIsGone() throws Exception {
        Process p = new ProcessBuilder("true").start();
        long pid = p.pid();
        p.waitFor();
        long deadline = System.nanoTime() + 5_000_000_000L;
        while (ProcessHandle.of(pid).isPresent() && System.nanoTime() < deadline) {
            Thread.onSpinWait();
        }
        assertTrue(ProcessHandle.of(pid).isEmpty(), "pid " + pid + " gone");
        return pid;
    }

    /** The regular files of the data folder named like a journal. */
    static Set<Path> journals(Path data) throws IOException {
        Set<Path> s = new TreeSet<>();
        try (DirectoryStream<Path> ds = Files.newDirectoryStream(data, "teach-rec-*.bin")) {
            for (Path p : ds) {
                if (Files.isRegularFile(p, LinkOption.NOFOLLOW_LINKS)) {
                    s.add(p);
                }
            }
        }
        return s;
    }

    @Test
    void theJournalOfAKilledTeachHalfIsRemovedAndNothingElse() throws Exception {
        CellRig.assertBuilt(CellRig.SIM_ROBOT, CellRig.TEACH, CellRig.FORCE_GUARD);
        try (Runtime rt = new Runtime("teach-journal")) {
            List<String> cell = new ArrayList<>(CellRig.installArm(rt));
            rt.installAndStart(CellRig.TEACH);
            cell.add("teach");
            rt.awaitState("ACTIVE", T, cell.toArray(String[]::new));
            rt.waitUntil("the arm follows teach", T, () -> CellRig.armFollows(rt, "teach"));

            // teach mode, a hand pulling the tool: a recording that no longer fits the state block
            CellRig.set(rt, "teach", "record_step", "0.0002");
            CellRig.set(rt, "teach", "teach", "true");
            CellRig.set(rt, "sim-robot", "guide_dx", "0");
            CellRig.set(rt, "sim-robot", "guide_dy", "0.15");
            CellRig.set(rt, "sim-robot", "guide_dz", "0");
            CellRig.set(rt, "sim-robot", "guide_duration_ms", "6000");
            CellRig.set(rt, "sim-robot", "guide_force_n", "60");
            rt.waitUntil("more than 200 waypoints recorded", T, () -> {
                ByteBuffer s = TeachUpdateIT.state(rt, "teach");
                return s != null && s.getInt(TeachUpdateIT.TS_REC_COUNT) > 200;
            });
            long pid = rt.pid("teach");
            ByteBuffer before = TeachUpdateIT.state(rt, "teach");
            assertEquals(pid, Integer.toUnsignedLong(before.getInt(TeachUpdateIT.TS_JOURNAL_PID)), "the block names the half");
            Path killed = TeachUpdateIT.journal(rt, before);
            Path data = killed.getParent();
            rt.waitUntil("the half's journal written", T, () -> Files.exists(killed));

            // planted: named like the journal of a half that is gone
            long gone = pidThatIsGone();
            Path victim = Files.writeString(rt.dir.resolve("victim.txt"), "precious\n");
            Path link = Files.createSymbolicLink(
                    data.resolve(String.format(Locale.ROOT, "teach-rec-%d-00000000000000aa.bin", gone)), victim);
            Path foreign = data.resolve(String.format(Locale.ROOT, "teach-rec-%d-00000000000000bb.bin", gone));
            boolean root = ((Number) Files.getAttribute(victim, "unix:uid")).intValue() == 0;
            if (root) {
                Files.writeString(foreign, "not a journal\n");
                Files.setPosixFilePermissions(foreign, java.nio.file.attribute.PosixFilePermissions.fromString("rw-------"));
                Files.setAttribute(foreign, "unix:uid", 12345);
            }

            int mark = rt.logMark();
            long t0 = System.nanoTime();
            ProcessHandle.of(pid).ifPresent(ProcessHandle::destroyForcibly); // SIGKILL
            rt.waitUntil("teach restarted", T, () -> rt.activeWithNewPid("teach", pid));
            long newPid = rt.pid("teach");
            rt.waitUntil("the killed half's journal removed", T, () -> !Files.exists(killed, LinkOption.NOFOLLOW_LINKS));
            long ms = (System.nanoTime() - t0) / 1_000_000;
            Path[] live = new Path[1];
            rt.waitUntil("the restarted half's journal", T, () -> {
                ByteBuffer s = TeachUpdateIT.state(rt, "teach");
                if (s == null || Integer.toUnsignedLong(s.getInt(TeachUpdateIT.TS_JOURNAL_PID)) != newPid) {
                    return false;
                }
                live[0] = TeachUpdateIT.journal(rt, s);
                return Files.exists(live[0]);
            });
            Set<Path> now = journals(data);
            List<String> log = rt.logSince(mark);
            List<String> teachLog = log.stream().filter(l -> l.contains("teach: ")).toList();
            System.out.println("TeachJournalIT: kill -9 of pid " + pid + ", restarted as pid " + newPid
                    + "; the killed half's journal gone " + ms + " ms after the kill; journals now " + now
                    + "\nTeachJournalIT: the restarted half's log:\n" + String.join("\n", teachLog));
            Set<Path> want = new TreeSet<>(root ? Set.of(live[0], foreign) : Set.of(live[0]));
            assertEquals(want, now, "the data folder holds the live half's journal (and the other uid's file)");
            assertTrue(Files.isSymbolicLink(link), "the symlink is left");
            assertEquals("precious\n", Files.readString(victim), "its target untouched");
            assertTrue(teachLog.stream().anyMatch(l -> l.contains("removed the journal") && l.contains(killed.getFileName().toString())
                    && l.contains("pid " + pid)), "the removal named in the log");
            assertTrue(teachLog.stream().anyMatch(l -> l.contains("not removed") && l.contains(link.getFileName().toString())
                    && l.contains("symbolic link")), "the symlink's refusal named in the log");
            if (root) {
                assertTrue(Files.exists(foreign), "the other uid's file is left");
                assertTrue(teachLog.stream().anyMatch(l -> l.contains("not removed") && l.contains(foreign.getFileName().toString())
                        && l.contains("belongs to uid 12345")), "the other uid's file's refusal named in the log");
            }
            Files.delete(link);
            Files.deleteIfExists(foreign);
        }
    }
}
