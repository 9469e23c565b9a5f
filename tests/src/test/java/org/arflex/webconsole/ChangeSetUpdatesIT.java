package org.arflex.webconsole;

import static org.arflex.webconsole.ChangeSetApi.PAGE;
import static org.arflex.webconsole.ChangeSetApi.applyInTheBrowser;
import static org.arflex.webconsole.ChangeSetApi.awaitLiveOutcome;
import static org.arflex.webconsole.ChangeSetApi.textOf;
import static org.arflex.webconsole.ChangeSetApi.updateRows;
import static org.arflex.webconsole.ConsoleJars.sha256;
import static org.arflex.webconsole.ConsoleJars.version;
import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.nio.file.Files;
import java.nio.file.Path;
import java.time.Duration;
import java.util.List;
import java.util.Map;
import java.util.regex.Pattern;
import org.junit.jupiter.api.BeforeAll;
import org.junit.jupiter.api.MethodOrderer;
import org.junit.jupiter.api.Order;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.TestMethodOrder;
import org.junit.jupiter.api.extension.RegisterExtension;

/**
 * Change sets that update running components, and the DRCR's history of sets, on the real
 * runtime with sample-counter and sample-scaler running: deployment sets refused before their
 * change set are in the history with their reason; an update of the scaler with a shadow run
 * and a rollback window applied from the page, whose live progress (D53) the page shows going
 * through the shadow run (its cycles) and the window to the outcome; then a set of two updates
 * (the counter with a window, the scaler with a shadow run and a window), whose rows the page
 * shows each with its own counters, kept with the outcome (D60) and in the history (D62).
 */
@TestMethodOrder(MethodOrderer.OrderAnnotation.class)
class ChangeSetUpdatesIT {
    private static final Duration WAIT = ChangeSetApi.WAIT;
    @RegisterExtension
    static final ConsoleFixture FX = ConsoleFixture.runtime("changeset-updates").started("sample-counter", "sample-scaler");
    private static ChangeSetApi api;

    @BeforeAll
    static void session() {
        api = new ChangeSetApi(FX.rt());
    }

    /**
     * D50: deployment sets refused before their change set, one for its descriptor, one by the
     * code gate, are in the DRCR's history as the page lists it: the action {@code deploy <url>},
     * refused, with the reason (the descriptor's line; the jar and both hashes); nothing applied.
     */
    @Test
    @Order(1)
    void deploymentSetsRefusedBeforeTheirChangeSetAreInTheHistoryWithTheirReason() throws IOException {
        Path dir = Files.createDirectories(FX.rt().work.resolve("sets"));
        Path bad = Files.writeString(dir.resolve("bad.xml"), "<deployment xmlns=\"urn:arflex:deployment:1\">\n"
                + "  <uninstall component=\"sample-counter\" jar=\"x.jar\"/>\n</deployment>\n");
        Path scaler = org.arflex.it.Components.jar("sample-scaler");
        String zeros = "0".repeat(64);
        Path pin = Files.writeString(dir.resolve("pin.xml"), "<deployment xmlns=\"urn:arflex:deployment:1\">\n"
                + "  <install jar=\"" + scaler.toUri() + "\" sha256=\"" + zeros + "\"/>\n</deployment>\n");
        int before = api.history().size();
        String scalerState = FX.state("sample-scaler");
        FX.rt().gogo("arflex:deploy set " + bad.toUri());
        FX.rt().gogo("arflex:deploy set " + pin.toUri());
        RuntimeUnderTest.awaitCondition("two refused deployment sets in the history", WAIT,
                () -> api.history().size() == before + 2);
        List<Map<String, Object>> h = api.history();
        Map<String, Object> gate = h.get(0);
        Map<String, Object> syntax = h.get(1);
        assertEquals(List.of("deploy " + bad.toUri()), syntax.get("actions"));
        assertEquals("refused", syntax.get("outcome"), String.valueOf(syntax));
        assertEquals(false, syntax.get("applied"));
        assertTrue(String.valueOf(syntax.get("why")).matches("descriptor: " + Pattern.quote(bad.toUri().toString())
                + ":2:\\d+: <uninstall>: unknown attribute 'jar' \\(allowed: component\\)"), String.valueOf(syntax));
        assertEquals(List.of("deploy " + pin.toUri()), gate.get("actions"));
        assertEquals("refused", gate.get("outcome"), String.valueOf(gate));
        String why = String.valueOf(gate.get("why"));
        assertTrue(why.startsWith("jar " + scaler.toUri() + " (line 2, install): ") && why.contains("pinned " + zeros)
                && why.endsWith("; nothing installed"), why);
        assertEquals(scalerState, FX.state("sample-scaler"), "nothing of the refused sets changed the cell");
    }

    @Test
    @Order(2)
    void thePageShowsAnUpdatesShadowRunAndWindowLiveToItsOutcome() throws IOException {
        Browser.requireInstalled();
        assertEquals("ACTIVE", FX.state("sample-scaler"), "the scaler runs");
        long scalerPid = FX.pid("sample-scaler");
        Path work = FX.rt().work;
        Path jar = version(Files.createDirectories(work.resolve(RuntimeUnderTest.STAGED).resolve("versions")),
                "sample-scaler", "1.0.1-live");
        // 10 ms cycles: 300 shadow cycles take 3 s, the window 200 cycles 2 s
        String set = "update sample-scaler " + jar.toUri() + " " + sha256(jar)
                + " shadow 300 tolerance y.value 0.000001 window 200";
        Path shots = Path.of(System.getProperty("arflex.screenshots", "target/screenshots"));
        try (Browser b = api.openPage(work.resolve("chromedriver-progress.log"))) {
            applyInTheBrowser(b, set);
            // live: the shadow run with its cycles counting and the worst deviation so far
            String shadow = b.await("the shadow run shown live, its cycles counting", WAIT, () -> {
                String phase = (String) b.js("const e = document.getElementById('arflex-cs-live-box');"
                        + " return e && e.dataset.running === 'true' ? e.dataset.phase : null;");
                String cycle = (String) b.js("const e = document.getElementById('arflex-cs-live-cycles');"
                        + " return e ? e.dataset.cycle : null;");
                return "shadow".equals(phase) && cycle != null && Long.parseLong(cycle) > 0
                        ? textOf(b, "#arflex-cs-live-box") : null;
            }, b::source);
            b.screenshot(shots.resolve("changesets-progress-shadow.png"));
            assertTrue(shadow.contains("Applying now: update sample-scaler"), shadow);
            assertTrue(shadow.contains("of 300 (sample-scaler)"), shadow);
            assertTrue(shadow.contains("update sample-scaler: shadow run of pid"), shadow);
            assertEquals(scalerPid, FX.pid("sample-scaler"), "nothing switched during the shadow run");
            String window = b.await("the rollback window shown live", WAIT, () -> {
                String phase = (String) b.js("const e = document.getElementById('arflex-cs-live-box');"
                        + " return e ? e.dataset.phase + '/' + e.dataset.running : null;");
                return "window/true".equals(phase) || (phase != null && phase.startsWith("done/"))
                        ? phase + " " + textOf(b, "#arflex-cs-live-box") : null;
            }, b::source);
            System.out.println("ChangeSetUpdatesIT: after the shadow run the page showed: " + window);
            String done = awaitLiveOutcome(b, "the outcome shown live");
            b.screenshot(shots.resolve("changesets-progress-done.png"));
            assertEquals("done/committed", done, textOf(b, "#arflex-cs-live-box"));
            @SuppressWarnings("unchecked")
            List<String> phases = (List<String>) b.js("return Array.from(document.querySelectorAll("
                    + "'#arflex-cs-live-phases li')).map(e => e.dataset.phase);");
            assertEquals(List.of("checking", "preparing", "shadow", "switching", "window", "bundles", "done"), phases);
        }
        // the endpoint says the same, and the new version runs
        Map<String, Object> p = Json.object(FX.rt().get(PAGE + "/api/changeset-progress", true).body());
        @SuppressWarnings("unchecked")
        Map<String, Object> last = (Map<String, Object>) p.get("progress");
        assertEquals("committed", last.get("outcome"), String.valueOf(p));
        assertTrue(String.valueOf(last.get("why")).contains("update sample-scaler: passed its shadow run of"), String.valueOf(p));
        RuntimeUnderTest.awaitCondition("the new version running", WAIT,
                () -> FX.pid("sample-scaler") != scalerPid && "ACTIVE".equals(FX.state("sample-scaler")));
        // the shell says the same: arflex:change progress, its output in the runtime's log
        FX.rt().gogo("arflex:change progress");
        RuntimeUnderTest.awaitCondition("arflex:change progress answered", WAIT,
                () -> FX.rt().tail().contains("outcome: committed: update sample-scaler: passed its shadow run of 3"));
        assertTrue(FX.rt().tail().contains("(phases checking > preparing > shadow > switching > window > bundles > done)\n"
                + "outcome: committed: update sample-scaler: passed its shadow run of 3"),
                FX.rt().tail());
    }

    @Test
    @Order(3)
    @SuppressWarnings("unchecked")
    void aSetOfTwoUpdatesShowsARowForEachToItsOutcome() throws IOException {
        Browser.requireInstalled();
        RuntimeUnderTest.awaitCondition("counter and scaler running", WAIT,
                () -> "ACTIVE".equals(FX.state("sample-counter")) && "ACTIVE".equals(FX.state("sample-scaler")));
        long counterPid = FX.pid("sample-counter");
        long scalerPid = FX.pid("sample-scaler");
        Path dir = Files.createDirectories(FX.rt().work.resolve(RuntimeUnderTest.STAGED).resolve("versions-two"));
        Path counter = version(dir, "sample-counter", "1.0.1-two");
        Path scaler = version(dir, "sample-scaler", "1.0.2-two");
        // the counter without a shadow run (its sine's phase is its own), the scaler with one; 10 ms cycles
        String set = "update sample-counter " + counter.toUri() + " " + sha256(counter) + " window 200\n"
                + "update sample-scaler " + scaler.toUri() + " " + sha256(scaler)
                + " shadow 300 tolerance y.value 0.000001 window 200";
        Path work = FX.rt().work;
        Path shots = Path.of(System.getProperty("arflex.screenshots", "target/screenshots"));
        try (Browser b = api.openPage(work.resolve("chromedriver-two.log"))) {
            applyInTheBrowser(b, set);
            // live: the scaler's row counts its shadow cycles while the counter's waits for the switch
            List<Map<String, String>> shadow = b.await("the scaler's shadow run in its row", WAIT, () -> {
                List<Map<String, String>> rows = updateRows(b);
                return rows.size() == 2 && "shadow".equals(rows.get(1).get("phase"))
                        && Long.parseLong(rows.get(1).get("cycle")) > 0 ? rows : null;
            }, b::source);
            b.screenshot(shots.resolve("changesets-progress-two-shadow.png"));
            System.out.println("ChangeSetUpdatesIT: two updates, in the scaler's shadow run: " + shadow);
            assertEquals(List.of("sample-counter", "sample-scaler"), shadow.stream().map(r -> r.get("component")).toList(),
                    "the rows in the set's order");
            assertEquals("", shadow.get(0).get("phase"), "the counter has no shadow run: " + shadow);
            assertEquals("300", shadow.get(1).get("cycles"));
            assertTrue(shadow.get(1).get("text").contains(" of 300"), shadow.toString());
            assertEquals(counterPid, FX.pid("sample-counter"), "nothing switched during the shadow run");
            assertEquals(scalerPid, FX.pid("sample-scaler"), "nothing switched during the shadow run");
            // both windows, each in its own row
            List<Map<String, String>> windows = b.await("both windows in their rows", WAIT, () -> {
                List<Map<String, String>> rows = updateRows(b);
                return rows.size() == 2 && rows.stream().allMatch(r -> "window".equals(r.get("phase"))) ? rows : null;
            }, b::source);
            System.out.println("ChangeSetUpdatesIT: two updates, in their windows: " + windows);
            String done = awaitLiveOutcome(b, "the outcome");
            b.screenshot(shots.resolve("changesets-progress-two-done.png"));
            assertEquals("done/committed", done, textOf(b, "#arflex-cs-live-box"));
            List<Map<String, String>> rows = updateRows(b);
            System.out.println("ChangeSetUpdatesIT: two updates, the outcome: " + rows);
            assertEquals(2, rows.size(), "the rows stay with the outcome: " + rows);
            for (Map<String, String> r : rows) {
                assertEquals("committed", r.get("verdict"), rows.toString());
                assertEquals("window", r.get("phase"), rows.toString());
                assertEquals("200", r.get("cycles"), rows.toString());
                assertTrue(Long.parseLong(r.get("cycle")) >= 200, "its last counters: " + rows);
            }
            assertEquals("", rows.get(0).get("worst"), "no shadow run, no deviation: " + rows);
            assertFalse(rows.get(1).get("worst").isEmpty(), "the scaler's shadow run's worst deviation kept: " + rows);
            // the history's newest row: each update as the DRCR kept it (D62)
            List<Map<String, String>> kept = b.await("the history's row with each update", WAIT, () -> {
                List<Map<String, String>> h = (List<Map<String, String>>) b.js("const r = document.querySelector("
                        + "'#arflex-cs-history-table tr[data-index=\"0\"]'); return r ? Array.from(r.querySelectorAll("
                        + "'div.arflex-cs-history-update')).map(e => ({component: e.dataset.component, phase: e.dataset.phase,"
                        + " cycle: e.dataset.cycle, cycles: e.dataset.cycles, worst: e.dataset.worst,"
                        + " verdict: e.dataset.verdict, text: e.innerText})) : [];");
                return h.size() == 2 ? h : null;
            }, b::source);
            System.out.println("ChangeSetUpdatesIT: two updates, the history's row: " + kept);
            assertEquals(List.of("sample-counter", "sample-scaler"), kept.stream().map(r -> r.get("component")).toList());
            for (Map<String, String> r : kept) {
                assertEquals("committed", r.get("verdict"), kept.toString());
                assertEquals("200", r.get("cycles"), kept.toString());
            }
            assertFalse(kept.get(1).get("worst").isEmpty(), kept.toString());
        }
        // the endpoint's history: the same entries
        List<Map<String, Object>> entries = (List<Map<String, Object>>) api.history().get(0).get("entries");
        assertEquals(List.of("sample-counter", "sample-scaler"), entries.stream().map(u -> u.get("component")).toList());
        assertEquals(List.of("committed", "committed"), entries.stream().map(u -> u.get("verdict")).toList());
        assertEquals("y.value", entries.get(1).get("worstField"), String.valueOf(entries));
        // the endpoint says the same
        Map<String, Object> p = Json.object(FX.rt().get(PAGE + "/api/changeset-progress", true).body());
        Map<String, Object> last = (Map<String, Object>) p.get("progress");
        List<Map<String, Object>> updates = (List<Map<String, Object>>) last.get("updates");
        assertEquals(List.of("sample-counter", "sample-scaler"), updates.stream().map(u -> u.get("component")).toList());
        assertNull(updates.get(0).get("worstField"), String.valueOf(updates));
        assertEquals("y.value", updates.get(1).get("worstField"), String.valueOf(updates));
        assertTrue(String.valueOf(updates.get(1).get("why")).startsWith("update sample-scaler: committed: the new version ran"),
                String.valueOf(updates));
        RuntimeUnderTest.awaitCondition("both new versions running", WAIT,
                () -> FX.pid("sample-counter") != counterPid && FX.pid("sample-scaler") != scalerPid);
        // the shell: a line per update
        FX.rt().gogo("arflex:change progress");
        RuntimeUnderTest.awaitCondition("arflex:change progress answered with a line per update", WAIT,
                () -> FX.rt().tail().contains("update sample-scaler: rollback window, cycle "));
        String tail = FX.rt().tail();
        assertTrue(tail.matches("(?s).*\nupdate sample-counter: rollback window, cycle \\d+ of 200; committed\n"
                + "update sample-scaler: rollback window, cycle \\d+ of 200, worst deviation in shadow y\\.value \\S+ "
                + "\\(tolerance 1\\.0E-6\\); committed.*"), tail);
        // and its history (D62): the same lines, kept
        FX.rt().gogo("arflex:change history 1");
        RuntimeUnderTest.awaitCondition("arflex:change history answered", WAIT,
                () -> FX.rt().tail().contains("1 of the "));
        String history = FX.rt().tail().substring(FX.rt().tail().lastIndexOf("1 of the "));
        assertTrue(history.matches("(?s)1 of the \\d+ change sets applied in this runtime, newest first\n"
                + "\\S+ \\S+ UTC  change set: update sample-counter .*\n  outcome: committed\n"
                + "  update sample-counter: rollback window, cycle \\d+ of 200; committed\n"
                + "  update sample-scaler: rollback window, cycle \\d+ of 200, worst deviation in shadow y\\.value \\S+ "
                + "\\(tolerance 1\\.0E-6\\); committed\n  prepared in .*"), history);
    }
}
