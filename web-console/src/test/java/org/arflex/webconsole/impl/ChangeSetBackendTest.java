package org.arflex.webconsole.impl;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertNotEquals;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.Map;
import org.arflex.drcr.ChangeSetService;
import org.arflex.drcr.dto.ChangeSetDTO;
import org.junit.jupiter.api.BeforeEach;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;

/**
 * The Change sets page's backend (D46) against a fake ChangeSetService that answers with the
 * DRCR's own text formats: the plan of the whole set read into its parts, a bad line named, an
 * apply refused when the plan shown is not the one the set gives now, and the outcomes read.
 */
class ChangeSetBackendTest {

    /** The DRCR's text of the dry run of {@code install teach; uninstall trajectory} (D35, ChangeSetIT). */
    static final String TEACH_PLAN = """
            change set: install teach; uninstall trajectory
            admitted (dry run: nothing changed)
            plan: change set: install teach 1.0.0, uninstall trajectory 1.0.0
            actions:
              REBIND   tcp-correction  input 'reference' <- teach.joint_ref (was trajectory.joint_ref)
              START    teach           installed; cpu 1: hyperbolic bound holds (U=0.15)
              STOP     trajectory      uninstalled
            stop order: trajectory
            start order: teach
            wiring:
              sim-robot.command <- tcp-correction.corrected
              tcp-correction.reference <- teach.joint_ref
            cpus:
              cpu 0  U=0.42/0.90  hyperbolic bound  sim-robot, force-guard
              cpu 1  U=0.15/0.90  hyperbolic bound  teach
              cpu 2  U=0.00/0.90  none
            memory: 97 MiB of 512 MiB; network: 0 B/s of 10 MB/s
            not active:
              trajectory  uninstalled
            """;

    private final List<List<String>> planned = new ArrayList<>();
    private final List<List<String>> applied = new ArrayList<>();
    private final List<Runnable> started = new ArrayList<>();
    private final List<Map<String, Object>> audited = new ArrayList<>();
    private String planText = TEACH_PLAN;
    private boolean admitted = true;
    private String refusal;
    private ChangeSetDTO applyAnswer;
    private org.arflex.drcr.dto.ChangeSetProgressDTO progressAnswer;
    private ChangeSetService service;
    private ChangeSetBackend backend;

    @BeforeEach
    void setUp() {
        service = new ChangeSetService() {
            @Override
            public ChangeSetDTO plan(List<String> actions) {
                planned.add(actions);
                ChangeSetDTO d = new ChangeSetDTO();
                d.actions = actions.toArray(String[]::new);
                d.admitted = admitted;
                d.refusal = refusal;
                d.text = planText;
                return d;
            }

            @Override
            public ChangeSetDTO apply(List<String> actions) {
                applied.add(actions);
                return applyAnswer;
            }

            @Override
            public ChangeSetDTO deploy(String url, boolean apply) {
                throw new AssertionError("no deployment set here");
            }

            @Override
            public List<ChangeSetDTO> history() {
                return applyAnswer == null ? List.of() : List.of(applyAnswer);
            }

            @Override
            public org.arflex.drcr.dto.ChangeSetProgressDTO progress() {
                return progressAnswer;
            }
        };
        backend = new ChangeSetBackend(() -> service, started::add,
                (user, remote, actions, view) -> audited.add(view), () -> 1_700_000_000_000L);
    }

    private static ChangeSetDTO answer(boolean applied, String refusal, String text) {
        ChangeSetDTO d = new ChangeSetDTO();
        d.actions = new String[] {"install teach", "uninstall trajectory"};
        d.applied = applied;
        d.admitted = refusal == null;
        d.refusal = refusal;
        d.text = text;
        d.prepareMs = applied ? 31.7 : 0;
        d.switchUs = applied ? 20_400 : 0;
        return d;
    }

    @Test
    @SuppressWarnings("unchecked")
    void thePlanOfTheWholeSetIsShownInItsPartsWithItsAdmission() throws Exception {
        Map<String, Object> r = backend.plan("# teach replaces the trajectory\ninstall teach\n\n  uninstall   trajectory  \n");
        assertEquals(List.of(List.of("install teach", "uninstall trajectory")), planned, "one action per line, as typed");
        assertEquals(List.of(2, 4), r.get("lines"));
        assertEquals(true, r.get("admitted"));
        Map<String, Object> p = (Map<String, Object>) r.get("parts");
        assertEquals("admitted (dry run: nothing changed)", p.get("outcomeLine"));
        assertEquals("change set: install teach 1.0.0, uninstall trajectory 1.0.0", p.get("title"));
        assertEquals(List.of(
                Map.of("op", "REBIND", "component", "tcp-correction", "reason",
                        "input 'reference' <- teach.joint_ref (was trajectory.joint_ref)"),
                Map.of("op", "START", "component", "teach", "reason", "installed; cpu 1: hyperbolic bound holds (U=0.15)"),
                Map.of("op", "STOP", "component", "trajectory", "reason", "uninstalled")), p.get("steps"));
        assertEquals("trajectory", p.get("stopOrder"));
        assertEquals("teach", p.get("startOrder"));
        assertEquals(List.of("sim-robot.command <- tcp-correction.corrected", "tcp-correction.reference <- teach.joint_ref"),
                p.get("wiring"));
        List<Map<String, Object>> cpus = (List<Map<String, Object>>) p.get("cpus");
        assertEquals(3, cpus.size());
        assertEquals("0", cpus.get(0).get("cpu"));
        assertEquals(0.42, cpus.get(0).get("utilisation"));
        assertEquals(0.90, cpus.get(0).get("cap"));
        assertEquals("hyperbolic bound", cpus.get(0).get("test"));
        assertEquals(List.of("sim-robot", "force-guard"), cpus.get(0).get("tasks"));
        assertEquals("none", cpus.get(2).get("test"));
        assertEquals(List.of(), cpus.get(2).get("tasks"));
        assertEquals("97 MiB of 512 MiB; network: 0 B/s of 10 MB/s", p.get("memory"));
        assertEquals(List.of(Map.of("component", "trajectory", "reason", "uninstalled")), p.get("notActive"));
        assertEquals(List.of(), p.get("after"), "every line of the plan is read into a part");
        assertEquals(TEACH_PLAN, r.get("text"), "and the text as the DRCR wrote it goes along");
        assertTrue(((String) r.get("planId")).matches("[0-9a-f]{64}"));
        assertTrue(started.isEmpty() && applied.isEmpty(), "planning applies nothing");
    }

    @Test
    void aRefusedSetNamesTheLineItIsAbout() throws Exception {
        admitted = false;
        refusal = "the set would stop 'tcp-correction' (input 'reference' of 'tcp-correction': ambiguous: "
                + "teach.joint_ref, trajectory.joint_ref): name it in the set";
        planText = "change set: install teach\nrefused: " + refusal + "\n";
        Map<String, Object> r = backend.plan("install teach\nset tcp-correction enable true\n");
        assertEquals(false, r.get("admitted"));
        assertEquals(refusal, r.get("refusal"));
        assertEquals(2, r.get("refusedLine"), "the quoted component is the one of line 2");
        refusal = "install lonely: not admitted: input 'x' of 'lonely': no provider";
        planText = "change set: uninstall a\nrefused: " + refusal + "\n";
        assertEquals(3, backend.plan("uninstall a\n\ninstall lonely\n").get("refusedLine"));
        // and applying a refused plan is refused, nothing applied
        String id = (String) backend.plan("uninstall a\n\ninstall lonely\n").get("planId");
        HttpError e = assertThrows(HttpError.class, () -> backend.apply("uninstall a\n\ninstall lonely\n", id, "u", "r"));
        assertEquals(409, e.status);
        assertTrue(e.getMessage().startsWith("the plan shown is refused, nothing was applied: install lonely")
                && e.getMessage().endsWith("(line 3)"), e.getMessage());
        assertTrue(applied.isEmpty() && started.isEmpty());
    }

    @Test
    void badInputIsRefusedNamingTheLineAndWhatIsWrongAndTheDrcrIsNotAsked() {
        String[][] cases = {
            {"install teach\ninstal trajectory", "line 2 ('instal trajectory'): unknown action 'instal'"},
            {"install teach\nuninstall", "line 2 ('uninstall'): uninstall takes one component (uninstall <component>), got 0"},
            {"install teach extra", "line 1 ('install teach extra'): install takes one component"},
            {"\n\nset teach mass", "line 3 ('set teach mass'): set takes <component> <parameter> <value>, got 2 words"},
            {"set teach Mass 3", "line 1 ('set teach Mass 3'): 'Mass' is not a parameter name"},
            {"install Teach", "line 1 ('install Teach'): 'Teach' is not a component name"},
            {"install teach; uninstall trajectory", "line 1 ('install teach; uninstall trajectory'): one action per line"},
            {"install teach\n\n\nupdate tcp-correction http://x/y.jar", "line 4 ('update tcp-correction http://x/y.jar'): "
                    + "the jar URL 'http://x/y.jar' is not https: or file:"},
            {"update tcp-correction", "line 1 ('update tcp-correction'): update takes <component> <jar URL>"},
            {"install te\u0000ach", "line 1: a character that is not printable ASCII (at column 11)"},
            {"install t\u00e9ach", "line 1: a character that is not printable ASCII (at column 10)"},
            {"", "actions: no action given"},
            {"# only a comment\n\n", "actions: only blank or comment lines"},
        };
        for (String[] c : cases) {
            HttpError e = assertThrows(HttpError.class, () -> backend.plan(c[0]), c[0]);
            assertEquals(400, e.status, c[0]);
            assertTrue(e.getMessage().startsWith(c[1]), "for '" + c[0] + "': " + e.getMessage());
        }
        String many = "uninstall a\n".repeat(ChangeSetInput.MAX_ACTIONS + 1);
        HttpError e = assertThrows(HttpError.class, () -> backend.plan(many));
        assertEquals("line 33: more than 32 actions in one set", e.getMessage());
        HttpError big = assertThrows(HttpError.class, () -> backend.plan("x".repeat(ChangeSetInput.MAX_TEXT + 1)));
        assertEquals(413, big.status);
        assertTrue(planned.isEmpty(), "no bad set reaches the DRCR");
    }

    @Test
    @SuppressWarnings("unchecked")
    void applyIsRefusedWhenTheCellChangedSinceThePlanWasShownAndNothingIsApplied() throws Exception {
        String set = "install teach\nuninstall trajectory";
        String shown = (String) backend.plan(set).get("planId");
        // meanwhile another provider came: the same set now plans another CPU for teach
        planText = TEACH_PLAN.replace("cpu 1: hyperbolic bound holds (U=0.15)", "cpu 2: hyperbolic bound holds (U=0.15)");
        HttpError e = assertThrows(HttpError.class, () -> backend.apply(set, shown, "arflex", "127.0.0.1"));
        assertEquals(409, e.status);
        assertTrue(e.getMessage().startsWith("the cell changed since the plan was shown: its plan is not the one you "
                + "confirmed, nothing was applied; plan the set again"), e.getMessage());
        assertTrue(applied.isEmpty() && started.isEmpty(), "nothing applied");
        assertNull(((Map<String, Object>) backend.status()).get("applying"));
        // the set as typed another way is the same set; an id that was never shown is refused
        String again = (String) backend.plan(set).get("planId");
        assertNotEquals(shown, again);
        assertEquals(400, assertThrows(HttpError.class, () -> backend.apply(set, "forged", "a", "r")).status);
        assertEquals(409, assertThrows(HttpError.class, () -> backend.apply(set, "0".repeat(64), "a", "r")).status);
        assertEquals(409, assertThrows(HttpError.class, () -> backend.apply("uninstall trajectory\ninstall teach", again,
                "a", "r")).status, "another order is another set: its plan was not shown");
        assertTrue(applied.isEmpty());

        // the plan shown, unchanged: applied on the runner's thread, one set at a time
        applyAnswer = answer(true, null, planText.replace("admitted (dry run: nothing changed)",
                "applied: prepared in 31.7 ms, switched in one actor turn of 20.400 ms") + "bundle 31 started\nbundle 30 stopped\n");
        Map<String, Object> r = backend.apply("install teach\n  uninstall trajectory\n", again, "arflex", "127.0.0.1");
        assertEquals("applying", r.get("state"));
        assertEquals(1, started.size());
        assertTrue(applied.isEmpty(), "the DRCR's apply runs off the HTTP thread");
        Map<String, Object> during = backend.status();
        assertEquals(List.of("install teach", "uninstall trajectory"), ((Map<String, Object>) during.get("applying")).get("actions"));
        HttpError busy = assertThrows(HttpError.class, () -> backend.apply(set, again, "b", "r"));
        assertEquals(409, busy.status);
        assertTrue(busy.getMessage().startsWith("another change set is being applied (install teach; uninstall trajectory"),
                busy.getMessage());
        started.get(0).run();
        assertEquals(List.of(List.of("install teach", "uninstall trajectory")), applied);
        Map<String, Object> after = backend.status();
        assertNull(after.get("applying"));
        Map<String, Object> last = (Map<String, Object>) after.get("last");
        assertEquals("committed", last.get("outcome"));
        assertEquals(true, last.get("planAsShown"), "the plan applied is the plan shown");
        assertEquals("arflex", last.get("user"));
        assertEquals(List.of("bundle 31 started", "bundle 30 stopped"), ((Map<String, Object>) last.get("parts")).get("after"));
        assertEquals(1, audited.size(), "the outcome goes to the audit log");
        assertEquals(1, ((List<?>) after.get("history")).size());
    }

    @Test
    void aPlanTheDrcrAppliedOtherwiseThanShownIsSaid() throws Exception {
        String set = "install teach\nuninstall trajectory";
        String id = (String) backend.plan(set).get("planId");
        applyAnswer = answer(true, null, TEACH_PLAN.replace("U=0.42/0.90", "U=0.55/0.90"));
        backend.apply(set, id, "u", "r");
        started.get(0).run();
        assertEquals(false, backend.status().get("last") instanceof Map<?, ?> m ? m.get("planAsShown") : null);
    }

    @Test
    void theOutcomesAreReadFromTheDrcrsAnswers() {
        Map<String, Object> shadow = ChangeSetOutcome.of(answer(false,
                "update tcp-correction: rejected in shadow after 92 cycles: the new version (pid 4242) exited: killed by "
                + "signal 11; nothing changed (pid 4100 runs tcp-correction on)", "change set: x\nrefused: ...\n"));
        assertEquals("rejected-in-shadow", shadow.get("outcome"));
        assertEquals(92L, shadow.get("cycles"));
        assertEquals("the new version (pid 4242) exited: killed by signal 11", shadow.get("why"));

        Map<String, Object> back = ChangeSetOutcome.of(answer(true, null, TEACH_PLAN
                + "update tcp-correction: rolled back after 192 cycles of the new version (file:/w/tc-1.0.2.jar): the new "
                + "version (pid 77) exited: killed by signal 11; pid 70 (tcp-correction) runs it again (its consumers bound "
                + "back 8.3 ms after the cause was seen)\n"));
        assertEquals("rolled-back", back.get("outcome"));
        assertEquals(192L, back.get("cycles"));
        assertEquals("the new version (pid 77) exited: killed by signal 11", back.get("why"));

        Map<String, Object> committed = ChangeSetOutcome.of(answer(true, null, TEACH_PLAN
                + "update tcp-correction: passed its shadow run of 201 cycles (0 cycles late, the running "
                + "version 0; 8 values compared)\n"
                + "update tcp-correction: committed: the new version ran 1000 cycles (0 cycles late, the "
                + "old one 0)\n"));
        assertEquals("committed", committed.get("outcome"));
        assertEquals(2, ((List<?>) committed.get("updates")).size());

        Map<String, Object> torn = ChangeSetOutcome.of(answer(false, "preparation failed, nothing changed: 'teach' (pid 9)"
                + " exited before the switch: exit 1", "change set: x\n"));
        assertEquals("torn-down", torn.get("outcome"));
        Map<String, Object> refused = ChangeSetOutcome.of(answer(false, "unknown component 'tech'", "change set: x\n"));
        assertEquals("refused", refused.get("outcome"));
        assertEquals("unknown component 'tech'", refused.get("why"));
        Map<String, Object> noVerdict = ChangeSetOutcome.of(answer(true, null, TEACH_PLAN
                + "warning: no verdict of the rollback window yet: java.util.concurrent.TimeoutException\n"));
        assertEquals("applied", noVerdict.get("outcome"));
        assertFalse(((String) noVerdict.get("why")).isEmpty());
    }

    @Test
    void withoutTheDrcrThePageSaysSo() throws Exception {
        service = null;
        assertEquals(503, assertThrows(HttpError.class, () -> backend.plan("install teach")).status);
        assertEquals(false, backend.status().get("drcr"));
        assertEquals(false, backend.progress().get("drcr"));
        assertNull(backend.progress().get("progress"));
    }

    @Test
    @SuppressWarnings("unchecked")
    void theProgressOfAnApplyIsTheDrcrsSnapshotAsJson() {
        assertNull(backend.progress().get("progress"), "no set applied in this runtime");
        assertEquals(true, backend.progress().get("drcr"));
        org.arflex.drcr.dto.ChangeSetProgressDTO p = new org.arflex.drcr.dto.ChangeSetProgressDTO();
        p.actions = new String[] {"update stage file:/x.jar"};
        p.running = true;
        p.phase = "shadow";
        p.phases = new String[] {"checking", "preparing", "shadow"};
        p.step = "update stage: shadow run of pid 7, cycle 40 of 100";
        p.component = "stage";
        p.cycle = 40;
        p.cycles = 100;
        p.worstField = "y.value";
        p.worstDeviation = 0.004;
        p.tolerance = 0.01;
        p.startedMillis = 1_700_000_000_000L - 2_500;
        p.seq = 17;
        progressAnswer = p;
        Map<String, Object> v = (Map<String, Object>) backend.progress().get("progress");
        assertEquals(List.of("update stage file:/x.jar"), v.get("actions"));
        assertEquals(true, v.get("running"));
        assertEquals("shadow", v.get("phase"));
        assertEquals(List.of("checking", "preparing", "shadow"), v.get("phases"));
        assertEquals(40L, v.get("cycle"));
        assertEquals(100L, v.get("cycles"));
        assertEquals("y.value", v.get("worstField"));
        assertEquals(0.004, v.get("worstDeviation"));
        assertEquals(2_500L, v.get("forMs"));
        assertEquals(17L, v.get("seq"));
        assertNull(v.get("outcome"));
        assertEquals(List.of(), v.get("updates"), "a DRCR that names no update");
        assertTrue(started.isEmpty() && applied.isEmpty(), "reading the progress applies nothing");
    }

    private static org.arflex.drcr.dto.UpdateProgressDTO entry(String component, String phase, long cycle, long cycles,
                                                              double worst, String verdict) {
        org.arflex.drcr.dto.UpdateProgressDTO u = new org.arflex.drcr.dto.UpdateProgressDTO();
        u.component = component;
        u.phase = phase;
        u.step = "update " + component + ": " + phase + " cycle " + cycle;
        u.cycle = cycle;
        u.cycles = cycles;
        u.worstField = "y.value";
        u.worstDeviation = worst;
        u.tolerance = 0.01;
        u.verdict = verdict;
        u.why = verdict == null ? null : "update " + component + ": " + verdict + ": why";
        return u;
    }

    @Test
    @SuppressWarnings("unchecked")
    void eachUpdateOfTheSetIsAnEntryInItsOrder() {
        org.arflex.drcr.dto.ChangeSetProgressDTO p = new org.arflex.drcr.dto.ChangeSetProgressDTO();
        p.actions = new String[] {"update src file:/s.jar", "update stage file:/x.jar"};
        p.running = false;
        p.phase = "done";
        p.phases = new String[] {"checking", "preparing", "shadow", "switching", "window", "done"};
        p.outcome = "committed";
        p.updates = new org.arflex.drcr.dto.UpdateProgressDTO[] {entry("src", "window", 50, 40, 0.002, "committed"),
                entry("stage", "window", 60, 50, 0.004, null)};
        progressAnswer = p;
        List<Map<String, Object>> u = (List<Map<String, Object>>) ((Map<String, Object>) backend.progress()
                .get("progress")).get("updates");
        assertEquals(2, u.size());
        assertEquals(List.of("src", "stage"), u.stream().map(e -> e.get("component")).toList());
        Map<String, Object> src = u.get(0);
        assertEquals("window", src.get("phase"));
        assertEquals(50L, src.get("cycle"));
        assertEquals(40L, src.get("cycles"));
        assertEquals("y.value", src.get("worstField"));
        assertEquals(0.002, src.get("worstDeviation"));
        assertEquals(0.01, src.get("tolerance"));
        assertEquals("committed", src.get("verdict"));
        assertEquals("update src: committed: why", src.get("why"));
        assertEquals("update src: window cycle 50", src.get("step"));
        assertEquals(60L, u.get(1).get("cycle"));
        assertEquals(0.004, u.get(1).get("worstDeviation"));
        assertNull(u.get(1).get("verdict"));
    }

    @Test
    @SuppressWarnings("unchecked")
    void theHistoryCarriesEachUpdatesEntryAsTheDrcrKeptIt() throws Exception {
        applyAnswer = answer(false, "update stage: rejected in shadow after 45 cycles: it exited; nothing changed (pid 9"
                + " runs stage on)", "change set: x\nrefused: ...\n");
        applyAnswer.outcome = "rejected-in-shadow";
        org.arflex.drcr.dto.UpdateProgressDTO src = entry("src", "shadow", 25, 100, 0.002, "cancelled");
        src.why = "cancelled: update stage was rejected in shadow (it exited)";
        applyAnswer.updates = new org.arflex.drcr.dto.UpdateProgressDTO[] {src,
                entry("stage", "shadow", 45, 200, 0.004, "rejected-in-shadow")};
        List<Map<String, Object>> h = (List<Map<String, Object>>) backend.status().get("history");
        assertEquals(1, h.size());
        List<Map<String, Object>> entries = (List<Map<String, Object>>) h.get(0).get("entries");
        assertEquals(List.of("src", "stage"), entries.stream().map(e -> e.get("component")).toList());
        assertEquals("cancelled", entries.get(0).get("verdict"));
        assertEquals("cancelled: update stage was rejected in shadow (it exited)", entries.get(0).get("why"));
        assertEquals(25L, entries.get(0).get("cycle"));
        assertEquals(100L, entries.get(0).get("cycles"));
        assertEquals(0.002, entries.get(0).get("worstDeviation"));
        assertEquals("rejected-in-shadow", entries.get(1).get("verdict"));
        assertEquals(45L, entries.get(1).get("cycle"));
        // the verdicts read from the text are as before
        assertEquals(List.of("stage"), ((List<Map<String, Object>>) h.get(0).get("updates")).stream()
                .map(e -> e.get("component")).toList());
        // a DRCR before 0.13 of its DTOs keeps no entries
        applyAnswer.updates = null;
        assertEquals(List.of(), ((List<Map<String, Object>>) backend.status().get("history")).get(0).get("entries"));
    }

    @Test
    void anUpdateFromAFileOutsideTheStagingFoldersIsRefusedBeforeTheDrcrReadsIt(@TempDir Path dir) throws Exception {
        // issue 30, finding 9: the page answered with the SHA-256 of any file the runtime can read
        String pin = " " + "0".repeat(64);
        for (String url : List.of("file:/etc/shadow", "file:/no/such/file.jar")) {
            HttpError e = assertThrows(HttpError.class, () -> backend.plan("install teach\nupdate sample-counter " + url
                    + pin));
            assertEquals(400, e.status);
            assertTrue(e.getMessage().startsWith("line 2: ") && e.getMessage().contains("file: URLs are refused"),
                    e.getMessage());
            assertThrows(HttpError.class, () -> backend.apply("update sample-counter " + url + pin, "a".repeat(64),
                    "alice", "127.0.0.1"));
        }
        assertEquals(List.of(), planned, "the DRCR never saw the location");

        Path folder = Files.createDirectories(dir.resolve("updates"));
        Path jar = Files.write(folder.resolve("counter.jar"), new byte[] {1});
        Files.writeString(dir.resolve("secret"), "s");
        ChangeSetBackend staged = new ChangeSetBackend(() -> service, started::add, (u, r, a, v) -> { },
                () -> 1_700_000_000_000L, StagingSources.parse(folder.toString()));
        HttpError outside = assertThrows(HttpError.class, () -> staged.plan("update sample-counter "
                + dir.resolve("updates/../secret").toUri() + pin));
        assertTrue(outside.getMessage().contains("is outside the folders configured"), outside.getMessage());
        assertEquals(List.of(), planned);
        staged.plan("update sample-counter " + jar.toUri() + pin);
        assertEquals(List.of(List.of("update sample-counter " + jar.toUri() + pin)), planned, "inside: planned");
    }
}
