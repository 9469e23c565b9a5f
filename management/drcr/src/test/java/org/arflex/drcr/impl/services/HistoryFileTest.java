package org.arflex.drcr.impl.services;

import static org.junit.jupiter.api.Assertions.assertArrayEquals;
import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.LinkOption;
import java.nio.file.Path;
import java.nio.file.attribute.PosixFilePermissions;
import java.util.ArrayList;
import java.util.List;
import java.util.concurrent.TimeUnit;
import java.util.concurrent.atomic.AtomicLong;
import java.util.stream.Stream;
import org.arflex.drcr.dto.ChangeSetDTO;
import org.arflex.drcr.dto.UpdateProgressDTO;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;

/**
 * The change-set history kept in the DRCR's data area (D66): a round trip through the file and
 * through a "restart" (a new store on the same folder), the bound, the atomic 0600 write, and
 * each file refused at the start (a link, not a regular file, another owner, open to others,
 * damaged, the wrong version, cut short): the log names the path and what is wrong, the file is
 * set aside unchanged (a link's target never touched), the history starts empty.
 */
class HistoryFileTest {

    @TempDir
    Path dir;

    private final List<String> log = new ArrayList<>();

    private long uid() throws IOException {
        return ((Number) Files.getAttribute(dir, "unix:uid")).longValue();
    }

    private HistoryFile file() throws IOException {
        return new HistoryFile(dir, uid(), log::add);
    }

    static ChangeSetDTO rejected() {
        ChangeSetDTO d = new ChangeSetDTO();
        d.actions = new String[] {"update sample-counter file:/a/c.jar 00ff window 200",
            "update sample-scaler file:/a/s.jar 11ee shadow 100 tolerance y.value 0.001"};
        d.admitted = true;
        d.applied = false;
        d.refusal = "update sample-scaler: rejected in shadow after 12 cycles:\toutput y.value = 2.5 \\ differs";
        d.text = "change set: ...\nrefused: ...\n  plan line \u00e9 \u2028 \u0001 end\n";
        d.finishedMillis = 1_764_192_000_123L;
        d.outcome = "rejected-in-shadow";
        UpdateProgressDTO c = new UpdateProgressDTO();
        c.component = "sample-counter";
        c.verdict = "cancelled";
        c.why = "cancelled: update sample-scaler was rejected in shadow (output y.value ...)";
        UpdateProgressDTO s = new UpdateProgressDTO();
        s.component = "sample-scaler";
        s.phase = "shadow";
        s.step = "shadow run: cycle 12 of 100";
        s.cycle = 12;
        s.cycles = 100;
        s.worstField = "y.value";
        s.worstDeviation = 0.5;
        s.tolerance = 1e-3;
        s.verdict = "rejected-in-shadow";
        s.why = "rejected";
        d.updates = new UpdateProgressDTO[] {c, s};
        return d;
    }

    static ChangeSetDTO committed(String action, long when) {
        ChangeSetDTO d = new ChangeSetDTO();
        d.actions = new String[] {action};
        d.admitted = true;
        d.applied = true;
        d.text = "change set: " + action + "\napplied\n";
        d.prepareMs = 12.5;
        d.switchUs = 67.6;
        d.finishedMillis = when;
        d.outcome = "applied";
        d.updates = new UpdateProgressDTO[0];
        return d;
    }

    static void assertSame(ChangeSetDTO a, ChangeSetDTO b) {
        assertArrayEquals(a.actions, b.actions);
        assertEquals(a.admitted, b.admitted);
        assertEquals(a.applied, b.applied);
        assertEquals(a.refusal, b.refusal);
        assertEquals(a.text, b.text);
        assertEquals(a.prepareMs, b.prepareMs);
        assertEquals(a.switchUs, b.switchUs);
        assertEquals(a.finishedMillis, b.finishedMillis);
        assertEquals(a.outcome, b.outcome);
        assertEquals(a.updates.length, b.updates.length);
        for (int i = 0; i < a.updates.length; i++) {
            UpdateProgressDTO x = a.updates[i];
            UpdateProgressDTO y = b.updates[i];
            assertEquals(x.component, y.component);
            assertEquals(x.phase, y.phase);
            assertEquals(x.step, y.step);
            assertEquals(x.cycle, y.cycle);
            assertEquals(x.cycles, y.cycles);
            assertEquals(x.worstField, y.worstField);
            assertEquals(x.worstDeviation, y.worstDeviation);
            assertEquals(x.tolerance, y.tolerance);
            assertEquals(x.verdict, y.verdict);
            assertEquals(x.why, y.why);
        }
    }

    private List<Path> entries() throws IOException {
        try (Stream<Path> s = Files.list(dir)) {
            return s.sorted().toList();
        }
    }

    private Path aside() throws IOException {
        List<Path> l = entries().stream().filter(p -> p.getFileName().toString().startsWith(HistoryFile.NAME + ".refused-"))
                .toList();
        assertEquals(1, l.size(), "one file set aside: " + entries());
        return l.get(0);
    }

    private String refusedLine() {
        List<String> l = log.stream().filter(s -> s.contains(" refused: ")).toList();
        assertEquals(1, l.size(), String.join("\n", log));
        assertTrue(l.get(0).contains(dir.resolve(HistoryFile.NAME).toString()), "names the path: " + l.get(0));
        assertTrue(l.get(0).endsWith("; the history starts empty"), l.get(0));
        return l.get(0);
    }

    @Test
    void roundTripKeepsEveryFieldOfEverySetAndItsUpdatesWrittenAtomically0600() throws IOException {
        HistoryFile f = file();
        assertEquals(List.of(), f.load(), "no file yet: empty, nothing logged as refused");
        f.write(List.of(rejected(), committed("install teach", 5)));
        Path p = dir.resolve(HistoryFile.NAME);
        assertEquals("rw-------", PosixFilePermissions.toString(Files.getPosixFilePermissions(p, LinkOption.NOFOLLOW_LINKS)));
        assertEquals(List.of(p), entries(), "no temporary file left");
        List<ChangeSetDTO> back = file().load();
        assertEquals(2, back.size());
        assertSame(rejected(), back.get(0));
        assertSame(committed("install teach", 5), back.get(1));
        assertTrue(log.stream().noneMatch(s -> s.contains("refused")), String.join("\n", log));
        // written again: replaced whole
        f.write(List.of(committed("uninstall teach", 9)));
        List<ChangeSetDTO> again = file().load();
        assertEquals(1, again.size());
        assertArrayEquals(new String[] {"uninstall teach"}, again.get(0).actions);
    }

    @Test
    void theStoreKeepsTheNewestFiftyAcrossARestart() throws IOException {
        AtomicLong now = new AtomicLong();
        HistoryStore store = HistoryStore.open(dir, uid(), log::add);
        ChangeSetHistory h = new ChangeSetHistory(now::get, store);
        h.record(rejected());
        for (int i = 0; i < ChangeSetHistory.MAX + 4; i++) {
            now.set(100 + i);
            h.record(committed("install c" + i, 0));
        }
        store.close(10_000);
        ChangeSetHistory after = new ChangeSetHistory(now::get, HistoryStore.open(dir, uid(), log::add));
        List<ChangeSetDTO> l = after.list();
        assertEquals(ChangeSetHistory.MAX, l.size());
        assertSame(h.list().get(0), l.get(0));
        assertEquals("install c" + (ChangeSetHistory.MAX + 3), l.get(0).actions[0]);
        assertEquals(100 + ChangeSetHistory.MAX + 3, l.get(0).finishedMillis);
        assertEquals("install c4", l.get(ChangeSetHistory.MAX - 1).actions[0], "the oldest (and the rejected) dropped");
        for (int i = 0; i < l.size(); i++) {
            assertSame(h.list().get(i), l.get(i));
        }
        // the file itself holds no more than the bound
        String text = Files.readString(dir.resolve(HistoryFile.NAME));
        assertEquals(ChangeSetHistory.MAX, text.lines().filter(s -> s.startsWith("set ")).count());
    }

    @Test
    void aStoreWithOneRecordKeepsItWithItsUpdateEntries() throws IOException {
        HistoryStore store = HistoryStore.open(dir, uid(), log::add);
        new ChangeSetHistory(() -> 77, store).record(rejected());
        store.close(10_000);
        List<ChangeSetDTO> l = new ChangeSetHistory(() -> 0, HistoryStore.open(dir, uid(), log::add)).list();
        assertEquals(1, l.size());
        ChangeSetDTO want = rejected();
        want.finishedMillis = 77;
        assertSame(want, l.get(0));
        assertEquals("cancelled", l.get(0).updates[0].verdict);
    }

    @Test
    void aFileWithMoreThanTheBoundIsReadToTheBound() throws IOException {
        List<ChangeSetDTO> many = new ArrayList<>();
        for (int i = 0; i < ChangeSetHistory.MAX + 10; i++) {
            many.add(committed("install c" + i, i));
        }
        file().write(many);
        List<ChangeSetDTO> l = file().load();
        assertEquals(ChangeSetHistory.MAX, l.size());
        assertEquals("install c0", l.get(0).actions[0], "the newest (first) kept");
    }

    @Test
    void aSymbolicLinkAtThePathIsNotFollowedItsTargetUntouched() throws IOException {
        Path victim = Files.createTempFile("victim", ".txt");
        try {
            Files.writeString(victim, "not the DRCR's");
            // even a link to a valid history is refused: it would be read and written through
            Path real = dir.resolve("elsewhere");
            file().write(List.of(committed("install a", 1)));
            Files.move(dir.resolve(HistoryFile.NAME), real);
            Files.createSymbolicLink(dir.resolve(HistoryFile.NAME), victim);
            HistoryStore store = HistoryStore.open(dir, uid(), log::add);
            ChangeSetHistory h = new ChangeSetHistory(() -> 3, store);
            assertEquals(List.of(), h.list());
            String line = refusedLine();
            assertTrue(line.contains("is a symbolic link (to " + victim + "): not followed"), line);
            Path aside = aside();
            assertTrue(Files.isSymbolicLink(aside), "the link itself set aside");
            assertTrue(line.contains("set aside as " + aside.getFileName()), line);
            h.record(committed("install b", 0));
            store.close(10_000);
            assertEquals("not the DRCR's", Files.readString(victim), "the link's target unchanged");
            Path p = dir.resolve(HistoryFile.NAME);
            assertTrue(Files.isRegularFile(p, LinkOption.NOFOLLOW_LINKS), "a new regular file in its place");
            assertEquals(1, file().load().size());
            assertTrue(Files.isRegularFile(real), "the other file untouched");
        } finally {
            Files.deleteIfExists(victim);
        }
    }

    @Test
    void aFolderAtThePathIsRefusedAndKept() throws IOException {
        Files.createDirectory(dir.resolve(HistoryFile.NAME));
        Files.writeString(dir.resolve(HistoryFile.NAME).resolve("inside"), "x");
        assertEquals(List.of(), file().load());
        assertTrue(refusedLine().contains("is not a regular file (a folder)"), refusedLine());
        assertEquals("x", Files.readString(aside().resolve("inside")));
    }

    @Test
    void aFifoAtThePathIsRefusedWithoutOpeningIt() throws Exception {
        Process p = new ProcessBuilder("mkfifo", dir.resolve(HistoryFile.NAME).toString()).start();
        assertTrue(p.waitFor(10, TimeUnit.SECONDS) && p.exitValue() == 0, "mkfifo");
        assertEquals(List.of(), file().load(), "returns at once: a FIFO is never opened");
        assertTrue(refusedLine().contains("is not a regular file (a device, FIFO or socket)"), refusedLine());
        aside();
    }

    @Test
    void aFileOpenToGroupOrOthersIsRefused() throws IOException {
        file().write(List.of(committed("install a", 1)));
        Path p = dir.resolve(HistoryFile.NAME);
        byte[] before = Files.readAllBytes(p);
        Files.setPosixFilePermissions(p, PosixFilePermissions.fromString("rw-r--r--"));
        assertEquals(List.of(), file().load());
        assertTrue(refusedLine().contains("has mode rw-r--r--: group or others may use it"), refusedLine());
        assertArrayEquals(before, Files.readAllBytes(aside()), "set aside unchanged");
        assertFalse(Files.exists(p, LinkOption.NOFOLLOW_LINKS));
    }

    @Test
    void aFileOfAnotherOwnerIsRefused() throws IOException {
        file().write(List.of(committed("install a", 1)));
        Path p = dir.resolve(HistoryFile.NAME);
        long other;
        if (uid() == 0) {
            Files.setAttribute(p, "unix:uid", 12345); // root can give it away: a real foreign file
            other = 12345;
        } else {
            other = uid(); // not root: the same check, against a runtime of another uid
        }
        HistoryFile f = new HistoryFile(dir, uid() == 0 ? 0 : uid() + 1, log::add);
        assertEquals(List.of(), f.load());
        long runtime = uid() == 0 ? 0 : uid() + 1;
        assertTrue(refusedLine().contains("belongs to uid " + other + ", not to the runtime's uid " + runtime),
                refusedLine());
        aside();
    }

    private String damaged(byte[] bytes) throws IOException {
        Path p = dir.resolve(HistoryFile.NAME);
        Files.write(p, bytes);
        Files.setPosixFilePermissions(p, PosixFilePermissions.fromString("rw-------"));
        assertEquals(List.of(), file().load());
        String line = refusedLine();
        assertTrue(line.contains(" refused: it is damaged: "), line);
        assertArrayEquals(bytes, Files.readAllBytes(aside()), "set aside as it was");
        return line;
    }

    private static byte[] good() {
        return HistoryFormat.write(List.of(rejected(), committed("install teach", 5)));
    }

    @Test
    void aFileCutShortIsRefusedSayingSo() throws IOException {
        byte[] g = good();
        String line = damaged(java.util.Arrays.copyOf(g, g.length / 2));
        assertTrue(line.contains("truncated: line "), line);
    }

    @Test
    void aFileCutAtALineEndIsRefusedSayingSo() throws IOException {
        String g = new String(good(), StandardCharsets.UTF_8);
        String cut = g.substring(0, g.lastIndexOf("end "));
        String line = damaged(cut.getBytes(StandardCharsets.UTF_8));
        assertTrue(line.contains("truncated: line " + (cut.lines().count() + 1) + " is past the last record and no end "
                + "line (2 records read)"), line);
    }

    @Test
    void aChangedByteIsRefusedByTheChecksum() throws IOException {
        String g = new String(good(), StandardCharsets.UTF_8);
        String line = damaged(g.replace("install teach", "install trash").getBytes(StandardCharsets.UTF_8));
        assertTrue(line.matches(".*line \\d+: end: SHA-256 [0-9a-f]{64} does not match the lines before it.*"), line);
    }

    @Test
    void aBadNumberIsRefusedNamingTheLineAndField() throws IOException {
        String g = new String(good(), StandardCharsets.UTF_8);
        String bad = g.replace("u.cycle 12\n", "u.cycle twelve\n");
        int no = (int) bad.substring(0, bad.indexOf("u.cycle twelve")).lines().count() + 1;
        String line = damaged(bad.getBytes(StandardCharsets.UTF_8));
        assertTrue(line.contains("line " + no + ": field u.cycle: 'twelve' is not a whole number"), line);
    }

    @Test
    void anUnknownFieldIsRefusedNamingIt() throws IOException {
        String g = new String(good(), StandardCharsets.UTF_8);
        String line = damaged(g.replace("outcome applied\n", "colour blue\n").getBytes(StandardCharsets.UTF_8));
        assertTrue(line.contains(": unknown field 'colour'"), line);
    }

    @Test
    void anotherVersionOrFormatIsRefusedNamingIt() throws IOException {
        String g = new String(good(), StandardCharsets.UTF_8);
        String line = damaged(g.replace(HistoryFormat.HEADER + " 1\n", HistoryFormat.HEADER + " 2\n")
                .getBytes(StandardCharsets.UTF_8));
        assertTrue(line.contains("line 1: version '2' is not one this DRCR reads (1)"), line);
    }

    @Test
    void jsonIsNotAHistory() throws IOException {
        String line = damaged("[{\"actions\":[]}]\n".getBytes(StandardCharsets.UTF_8));
        assertTrue(line.contains("line 1: not a change-set history (expected 'arflex change-set history 1', found "
                + "'[{\"actions\":[]}]')"), line);
    }

    @Test
    void aRefusedFileIsNeverSetAsideOverAnEarlierOne() throws IOException {
        for (int i = 0; i < 3; i++) {
            Path p = dir.resolve(HistoryFile.NAME);
            Files.writeString(p, "bad " + i + "\n");
            Files.setPosixFilePermissions(p, PosixFilePermissions.fromString("rw-------"));
            assertEquals(List.of(), file().load());
        }
        List<String> kept = new ArrayList<>();
        for (Path p : entries()) {
            kept.add(Files.readString(p));
        }
        assertEquals(List.of("bad 0\n", "bad 1\n", "bad 2\n"), kept.stream().sorted().toList(), "each kept: " + entries());
    }

    @Test
    void aTemporaryFileLeftByACutWriteIsSwept() throws IOException {
        file().write(List.of(committed("install a", 1)));
        Path tmp = dir.resolve(HistoryFile.NAME + ".0123456789abcdef.tmp");
        Files.writeString(tmp, "half");
        assertEquals(1, file().load().size());
        assertFalse(Files.exists(tmp));
        assertNull(log.stream().filter(s -> s.contains("refused")).findFirst().orElse(null));
    }
}
