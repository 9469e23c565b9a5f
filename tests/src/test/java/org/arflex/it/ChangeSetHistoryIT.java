package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.file.Files;
import java.nio.file.LinkOption;
import java.nio.file.Path;
import java.nio.file.attribute.PosixFilePermissions;
import java.util.List;
import java.util.Map;
import java.util.regex.Matcher;
import java.util.regex.Pattern;
import java.util.stream.Stream;
import org.junit.jupiter.api.Test;

/**
 * docs/DECISIONS.md D66 (and D62's cancelled verdict) through the real runtime, with
 * sample-counter and sample-scaler (10 ms cycles, real RT halves):
 * <ul>
 * <li>a set of two updates, the counter's without a shadow run and the scaler's with one whose
 * new version's gain (2.5) differs from the running version's (2.0): the scaler's is rejected in
 * shadow, the counter's entry says {@code cancelled: update sample-scaler was rejected in shadow
 * (...)} in {@code arflex:change progress} and in the history, nothing of the set is applied
 * (the same pids and versions, no new half left); then the DRCR bundle is stopped and started
 * ({@code stop N}/{@code start N}) and {@code arflex:change history 1} prints the same record,
 * with both entries, from the file in the DRCR's data area;</li>
 * <li>a symbolic link planted at that file's path while the DRCR is stopped: at its start the
 * link is not followed (its target unchanged, the log names the path and says so), the history
 * starts empty, and the next record is written as a new regular file in its place.</li>
 * </ul>
 */
class ChangeSetHistoryIT {

    static final long T = CellRig.T;
    static final Path SAMPLE_COUNTER = ShadowRunIT.SAMPLE_COUNTER;
    static final Path SAMPLE_SCALER = ShadowRunIT.SAMPLE_SCALER;
    private static final Pattern DRCR = Pattern.compile("(?m)^\\s*(\\d+)\\|.*\\|org\\.arflex\\.drcr \\(");

    /** The DRCR bundle's id, from {@code lb -s}. */
    static long drcrBundle(Runtime rt) {
        String lb = rt.cmd("lb -s");
        Matcher m = DRCR.matcher(lb);
        assertTrue(m.find(), "the DRCR in lb -s:\n" + lb);
        return Long.parseLong(m.group(1));
    }

    /** The history file in the DRCR bundle's data area. */
    static Path historyFile(Runtime rt, long drcr) {
        return rt.dir.resolve("felix-cache").resolve("bundle" + drcr).resolve("data").resolve("changeset-history");
    }

    static void stopDrcr(Runtime rt, long drcr) {
        int mark = rt.logMark();
        assertEquals("", rt.cmd("stop " + drcr, 180));
        rt.waitUntil("the DRCR stopped", T, () -> rt.logSince(mark).stream().anyMatch(l -> l.contains("arflex: DRCR stopped")));
    }

    static void startDrcr(Runtime rt, long drcr) {
        assertEquals("", rt.cmd("start " + drcr, 120));
        rt.waitUntil("the DRCR started again", 60_000, () -> rt.cmd("arflex:dto").startsWith("{"));
    }

    static void samples(Runtime rt) {
        rt.installAndStart(SAMPLE_COUNTER);
        rt.installAndStart(SAMPLE_SCALER);
        rt.awaitState("ACTIVE", T, "sample-counter", "sample-scaler");
    }

    @Test
    void aSetWhoseOtherUpdateIsRejectedInShadowIsCancelledAndItsRecordOutlivesADrcrRestart() throws Exception {
        CellRig.assertBuilt(SAMPLE_COUNTER, SAMPLE_SCALER);
        try (Runtime rt = new Runtime("history-cancelled")) {
            samples(rt);
            Path dir = Files.createDirectories(rt.dir.resolve("versions"));
            Path counter = ShadowRunIT.version(dir, SAMPLE_COUNTER, "sample-counter-1.0.1-two",
                    "OSGI-INF/arflex/sample-counter.xml", ShadowRunIT.versioned("sample-counter", "1.0.1-two"), null, null);
            // ShadowRunIT's diverging scaler: its gain 2.5 against the running 2.0
            Path scaler = ShadowRunIT.version(dir, SAMPLE_SCALER, "sample-scaler-1.0.2-gain",
                    "OSGI-INF/arflex/sample-scaler.xml", xml -> ShadowRunIT.versioned("sample-scaler", "1.0.2-gain")
                            .apply(xml).replace("default=\"2.0\" min=\"-10\" max=\"10\"",
                                    "default=\"2.5\" min=\"2.1\" max=\"10\""), null, null);
            Map<String, Long> before = ShadowRunIT.pids(rt);
            String counterInfo = rt.cmd("arflex:info sample-counter").lines().findFirst().orElse("");
            String scalerInfo = rt.cmd("arflex:info sample-scaler").lines().findFirst().orElse("");
            String out = rt.cmd("arflex:change apply update sample-counter file:" + counter + " "
                    + UpdateSetIT.sha256(counter) + " window 200 update sample-scaler file:" + scaler + " "
                    + UpdateSetIT.sha256(scaler) + " shadow 100 tolerance y.value 0.001", 120);
            System.out.println("ChangeSetHistoryIT: apply:\n" + out);
            assertTrue(out.contains("\nrefused: update sample-scaler: rejected in shadow after "), out);

            String progress = rt.cmd("arflex:change progress");
            System.out.println("ChangeSetHistoryIT: progress:\n" + progress);
            assertTrue(progress.contains("outcome: rejected-in-shadow"), progress);
            Matcher cancelled = Pattern.compile("update sample-counter: [^\n]*; cancelled: update sample-scaler was "
                    + "rejected in shadow \\([^\n]*y\\.value[^\n]*\\)").matcher(progress);
            assertTrue(cancelled.find(), progress);
            assertTrue(Pattern.compile("update sample-scaler: shadow run, cycle \\d+ of 100[^\n]*; rejected-in-shadow")
                    .matcher(progress).find(), progress);

            // nothing of the set applied: the same halves, versions and no new half left
            rt.waitUntil("no half of the set left", T, () -> Runtime.rtProcesses(rt.rid).stream()
                    .noneMatch(p -> p.contains("--instance 1-sample-")) && Files.list(Path.of("/dev/shm"))
                    .noneMatch(f -> f.getFileName().toString().startsWith("arflex." + rt.rid + ".1-sample-")));
            assertEquals(before, ShadowRunIT.pids(rt), "every half runs on with its pid");
            assertEquals(counterInfo, rt.cmd("arflex:info sample-counter").lines().findFirst().orElse(""));
            assertEquals(scalerInfo, rt.cmd("arflex:info sample-scaler").lines().findFirst().orElse(""));

            String history = rt.cmd("arflex:change history 1");
            System.out.println("ChangeSetHistoryIT: history before the restart:\n" + history);
            assertTrue(history.contains("  outcome: rejected-in-shadow: update sample-scaler: rejected in shadow after "),
                    history);
            assertTrue(history.contains(cancelled.group()), "the history's counter line is the progress's:\n" + history);

            long drcr = drcrBundle(rt);
            Path file = historyFile(rt, drcr);
            rt.waitUntil("the history written to " + file, T, () -> Files.isRegularFile(file, LinkOption.NOFOLLOW_LINKS)
                    && Files.readString(file).contains("u.verdict cancelled"));
            assertEquals("rw-------", PosixFilePermissions.toString(Files.getPosixFilePermissions(file)));

            stopDrcr(rt, drcr);
            int mark = rt.logMark();
            startDrcr(rt, drcr);
            String after = rt.cmd("arflex:change history 1");
            System.out.println("ChangeSetHistoryIT: history after the DRCR's restart:\n" + after);
            assertEquals(history, after, "the same record, with its entries, after the restart");
            assertTrue(rt.logSince(mark).stream().anyMatch(l -> l.contains("arflex: change-set history: 1 sets read from "
                    + file)), String.join("\n", rt.logSince(mark)));
            rt.awaitState("ACTIVE", T, "sample-counter", "sample-scaler");
        }
    }

    @Test
    void aSymbolicLinkPlantedAtTheHistoryFileIsNotFollowedAndTheLogNamesIt() throws Exception {
        CellRig.assertBuilt(SAMPLE_COUNTER, SAMPLE_SCALER);
        try (Runtime rt = new Runtime("history-link")) {
            samples(rt);
            // a set refused by the cell is recorded too: the cheapest record
            String refused = rt.cmd("arflex:change apply uninstall no-such-component");
            assertTrue(refused.startsWith("error: "), refused);
            long drcr = drcrBundle(rt);
            Path file = historyFile(rt, drcr);
            rt.waitUntil("the history written", T, () -> Files.isRegularFile(file, LinkOption.NOFOLLOW_LINKS));
            stopDrcr(rt, drcr);

            Path victim = rt.dir.resolve("victim.txt");
            Files.writeString(victim, "the attacker's target: not the DRCR's\n");
            Files.delete(file);
            Files.createSymbolicLink(file, victim);
            int mark = rt.logMark();
            startDrcr(rt, drcr);
            List<String> log = rt.logSince(mark);
            String line = log.stream().filter(l -> l.contains("arflex: change-set history: " + file + " refused: it is a "
                    + "symbolic link (to " + victim + "): not followed; set aside as changeset-history.refused-"))
                    .findFirst().orElse(null);
            assertTrue(line != null, "the log names the link:\n" + String.join("\n", log));
            System.out.println("ChangeSetHistoryIT: " + line);
            assertEquals("no change set in the history (the newest 50 are kept in the DRCR's data area, across restarts)",
                    rt.cmd("arflex:change history"));

            String again = rt.cmd("arflex:change apply uninstall no-such-component-2");
            assertTrue(again.startsWith("error: "), again);
            rt.waitUntil("the history written as a regular file", T,
                    () -> Files.isRegularFile(file, LinkOption.NOFOLLOW_LINKS));
            assertEquals("the attacker's target: not the DRCR's\n", Files.readString(victim), "the link's target unchanged");
            try (Stream<Path> s = Files.list(file.getParent())) {
                List<Path> aside = s.filter(p -> p.getFileName().toString().startsWith("changeset-history.refused-")).toList();
                assertEquals(1, aside.size());
                assertTrue(Files.isSymbolicLink(aside.get(0)), "the link itself was set aside");
            }
            assertFalse(rt.cmd("arflex:change history").contains("no-such-component\n"), "the old record not read");
            assertTrue(rt.cmd("arflex:change history").contains("uninstall no-such-component-2"));
        }
    }
}
