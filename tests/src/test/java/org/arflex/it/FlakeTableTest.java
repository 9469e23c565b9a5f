package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.List;
import java.util.concurrent.TimeUnit;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;

/**
 * {@code scripts/flake_table.py}, the table of {@code ./arflex bench flakes} (issue 32): per test
 * case, in how many runs it failed, errored or did not run, over report folders written here.
 */
class FlakeTableTest {

    static final Path SCRIPT = Components.root().resolve("scripts/flake_table.py");

    record Run(int status, String out) {
        List<String> lines() {
            return out.lines().toList();
        }

        String last() {
            List<String> l = lines();
            return l.isEmpty() ? "" : l.get(l.size() - 1);
        }
    }

    /** A Failsafe report of {@code cls} in run {@code k}: each case "name" passes, "name!" fails. */
    static void report(Path dir, int k, String cls, String... cases) throws IOException {
        StringBuilder x = new StringBuilder("<?xml version=\"1.0\"?>\n<testsuite name=\"" + cls + "\">\n");
        for (String c : cases) {
            boolean fails = c.endsWith("!");
            String name = fails ? c.substring(0, c.length() - 1) : c;
            x.append(" <testcase classname=\"").append(cls).append("\" name=\"").append(name).append("\">");
            if (fails) {
                x.append("<failure message=\"").append(name).append(" lost a click in run ").append(k).append("\"/>");
            }
            x.append("</testcase>\n");
        }
        Path f = dir.resolve("run-" + k).resolve("TEST-" + cls + ".xml");
        Files.createDirectories(f.getParent());
        Files.writeString(f, x.append("</testsuite>\n"));
    }

    static Run table(Path dir, String... more) throws Exception {
        List<String> cmd = new java.util.ArrayList<>(List.of("python3", SCRIPT.toString(), dir.toString()));
        cmd.addAll(List.of(more));
        Process p = new ProcessBuilder(cmd).redirectErrorStream(true).start();
        String out = new String(p.getInputStream().readAllBytes(), StandardCharsets.UTF_8);
        assertTrue(p.waitFor(60, TimeUnit.SECONDS), "flake_table.py did not end");
        return new Run(p.exitValue(), out);
    }

    @Test
    void aTestThatFailedInOneRunOfThreeIsNamedWithItsCountAndFirstMessage(@TempDir Path dir) throws Exception {
        report(dir, 1, "p.AIT", "start", "stop");
        report(dir, 2, "p.AIT", "start!", "stop");
        report(dir, 3, "p.AIT", "start", "stop");
        report(dir, 1, "p.BIT", "one");
        report(dir, 2, "p.BIT", "one");
        report(dir, 3, "p.BIT", "one");
        Path json = dir.resolve("flakes.json");
        Run r = table(dir, "--json", json.toString());
        assertEquals(0, r.status(), r.out());
        assertEquals("flakes: 3 tests, 1 failed at least once in 3 runs", r.last(), r.out());
        assertTrue(r.lines().stream().anyMatch(l -> l.startsWith("p.AIT.start") && l.contains("1/3")
                && l.contains("start lost a click in run 2")), r.out());
        assertTrue(r.lines().stream().noneMatch(l -> l.startsWith("p.AIT.stop") || l.startsWith("p.BIT.one")), r.out());
        String j = Files.readString(json);
        assertTrue(j.contains("\"runs\": 3") && j.contains("\"run-2\""), j);
    }

    @Test
    void aTestMissingFromARunCountsAsFailedThereAndAnEmptyRunIsNamed(@TempDir Path dir) throws Exception {
        report(dir, 1, "p.AIT", "start", "stop");
        report(dir, 2, "p.AIT", "start");
        Files.createDirectories(dir.resolve("run-3"));
        Run r = table(dir);
        assertEquals(0, r.status(), r.out());
        assertTrue(r.out().contains("run-3: no report at all"), r.out());
        assertTrue(r.lines().stream().anyMatch(l -> l.startsWith("p.AIT.stop") && l.contains("2/3")), r.out());
        assertTrue(r.lines().stream().anyMatch(l -> l.startsWith("p.AIT.start") && l.contains("1/3")
                && l.contains("not run")), r.out());
        assertEquals("flakes: 2 tests, 2 failed at least once in 3 runs", r.last(), r.out());
    }

    @Test
    void aFolderWithoutRunsIsRefusedNamingIt(@TempDir Path dir) throws Exception {
        Run r = table(dir);
        assertEquals(2, r.status(), r.out());
        assertTrue(r.out().contains(dir + ": no run-K folders"), r.out());
    }
}
