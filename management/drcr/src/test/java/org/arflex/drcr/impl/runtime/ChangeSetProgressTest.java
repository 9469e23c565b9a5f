package org.arflex.drcr.impl.runtime;

import static org.arflex.drcr.impl.runtime.UpdateRig.IN_SRC;
import static org.arflex.drcr.impl.runtime.UpdateRig.NEW_Y;
import static org.arflex.drcr.impl.runtime.UpdateRig.OLD_Y;
import static org.arflex.drcr.impl.runtime.UpdateRig.OUT;
import static org.arflex.drcr.impl.runtime.UpdateRig.parse;
import static org.arflex.drcr.impl.runtime.UpdateRig.sample;
import static org.junit.jupiter.api.Assertions.assertArrayEquals;
import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.concurrent.CompletableFuture;
import java.util.concurrent.atomic.AtomicLong;
import org.arflex.drcr.dto.ChangeSetProgressDTO;
import org.arflex.drcr.dto.UpdateProgressDTO;
import org.arflex.drcr.impl.abi.ControlBlock;
import org.arflex.drcr.impl.lifecycle.ManualActor;
import org.junit.jupiter.api.AfterEach;
import org.junit.jupiter.api.Test;

/**
 * The live progress of an apply (D53), read as the console and the shell read it, between the
 * actor's steps: the phases an update with a shadow run and a rollback window goes through, its
 * cycles and the worst deviation so far, then the outcome; a rejected one; and which apply is
 * shown when two begin. The cell of {@link CellShadowRunTest}: {@code src} -> {@code stage} ->
 * {@code user}, steppable actor, fake halves.
 */
class ChangeSetProgressTest {

    private final UpdateRig rig = new UpdateRig();
    private final FakeLauncher fake = rig.fake;
    private final ManualActor actor = rig.actor;
    private final Cell cell = rig.cell;
    /** Every distinct snapshot seen between steps, in order. */
    private final List<ChangeSetProgressDTO> seen = new ArrayList<>();

    @AfterEach
    void nothingLeaks() {
        rig.close();
    }

    private void runningCell() throws Exception {
        rig.runningCell("50us", "");
    }

    private ChangeSet update(long shadow, long window) throws Exception {
        return UpdateRig.update(parse("stage", "stage", IN_SRC + OUT, "1.1.0"), window, shadow,
                List.of(new ChangeSet.Tolerance("y", "value", 0.01)));
    }

    private static ControlBlock.Stats cycles(long n) {
        return UpdateRig.cycles(n, 0);
    }

    /** The snapshot now, as a reader off the actor gets it; recorded when it moved. */
    private ChangeSetProgressDTO now() {
        ChangeSetProgressDTO p = cell.changeSetProgress().snapshot();
        if (p != null && (seen.isEmpty() || seen.get(seen.size() - 1).seq != p.seq)) {
            assertTrue(seen.isEmpty() || seen.get(seen.size() - 1).seq < p.seq, "seq grows");
            seen.add(p);
        }
        return p;
    }

    private void look() {
        rig.look();
        now();
    }

    private CompletableFuture<ChangeSetResult> applyIntoShadow(ChangeSet set) {
        CompletableFuture<ChangeSetResult> f = rig.applyIntoShadow(set, this::now);
        now();
        return f;
    }

    private List<String> phasesSeen() {
        List<String> out = new ArrayList<>();
        for (ChangeSetProgressDTO p : seen) {
            if (out.isEmpty() || !out.get(out.size() - 1).equals(p.phase)) {
                out.add(p.phase);
            }
        }
        return out;
    }

    @Test
    void anUpdateGoesThroughPreparingShadowSwitchingAndItsWindowToItsOutcome() throws Exception {
        runningCell();
        assertNull(cell.changeSetProgress().snapshot(), "no set applied yet");
        CompletableFuture<ChangeSetResult> f = applyIntoShadow(update(100, 50));
        ChangeSetProgressDTO p = now();
        assertTrue(p.running);
        assertEquals("shadow", p.phase, p.step);
        assertArrayEquals(new String[] {"checking", "preparing", "shadow"}, p.phases);
        assertArrayEquals(new String[] {"update stage file:/x/stage-1.1.jar"},
                p.actions);
        assertEquals(100, p.cycles);
        assertEquals(0, p.cycle);
        assertTrue(seen.stream().anyMatch(s -> "preparing".equals(s.phase) && s.step.equals("0 of 1 new RT halves READY; "
                + "awaiting update stage")), () -> seen.stream().map(s -> s.phase + ": " + s.step).toList().toString());
        // 40 of its 100 shadow cycles, one value compared 0.004 from the running version's
        FakeLauncher.FakeHalf newHalf = fake.running.get("1-stage");
        fake.values.put(OLD_Y, sample(500, 7_000, 1.000));
        fake.values.put(NEW_Y, sample(3, 7_000, 1.004));
        newHalf.stats = cycles(40);
        look();
        p = now();
        assertEquals("shadow", p.phase);
        assertEquals("stage", p.component);
        assertEquals(40, p.cycle);
        assertEquals(100, p.cycles);
        assertEquals("y.value", p.worstField);
        assertEquals(0.004, p.worstDeviation, 1e-9);
        assertEquals(0.01, p.tolerance);
        assertTrue(p.step.startsWith("update stage: shadow run of pid " + newHalf.pid + ", cycle 40 of 100, 1 values "
                + "compared, 0 cycles late, worst y.value 0.00400 from the running version's (tolerance "
                + "0.01)"), p.step);
        // a set of one update: its one entry says what the fields above say (D60)
        assertEquals(1, p.updates.length);
        assertEntry(p.updates[0], "stage", "shadow", 40, 100, 0.004, null);
        assertEquals(p.step, p.updates[0].step);
        assertFalse(f.isDone());
        // passed: switched, then its window of 50 cycles
        newHalf.stats = cycles(100);
        look();
        rig.stepUntil("the switch", () -> {
            now();
            return f.isDone();
        });
        rig.stepUntil("the window's baseline", () -> "window".equals(now().phase) && now().cycles == 50);
        newHalf.stats = cycles(130);
        look();
        p = now();
        assertEquals("window", p.phase);
        assertEquals(30, p.cycle);
        assertEquals(50, p.cycles);
        assertTrue(p.step.startsWith("update stage: rollback window, cycle 30 of 50 of pid " + newHalf.pid), p.step);
        assertTrue(p.running);
        newHalf.stats = cycles(160);
        look();
        rig.stepUntil("the verdict", () -> f.join().verdict().isDone() && !now().running);
        p = now();
        assertEquals("done", p.phase);
        assertEquals("committed", p.outcome);
        assertTrue(p.why.contains("update stage: committed: the new version ran 60 cycles"), p.why);
        assertEquals(1, p.updates.length);
        assertEntry(p.updates[0], "stage", "window", 60, 50, 0.004, "committed");
        assertTrue(p.updates[0].why.startsWith("update stage: committed: the new version ran 60 cycles"),
                p.updates[0].why);
        assertArrayEquals(new String[] {"checking", "preparing", "shadow", "switching", "window", "done"}, p.phases);
        // every phase was seen live too, but the executor's checks and the switch (each within one actor
        // turn, between two reads)
        assertEquals(List.of("preparing", "shadow", "window", "done"), phasesSeen(), phasesSeen()::toString);
        // what a reader got is a copy: changing it changes nothing shown
        p.phase = "forged";
        p.phases[0] = "forged";
        assertEquals("done", now().phase);
        assertEquals("checking", now().phases[0]);
    }

    @Test
    void anUpdateRejectedInShadowEndsWithThatOutcomeAndNeverSwitches() throws Exception {
        runningCell();
        CompletableFuture<ChangeSetResult> f = applyIntoShadow(update(200, 1000));
        FakeLauncher.FakeHalf newHalf = fake.running.get("1-stage");
        newHalf.stats = cycles(20);
        look();
        assertEquals(20, now().cycle);
        newHalf.crash(139, "killed by signal 11");
        rig.stepUntil("the outcome", () -> {
            now();
            return f.isDone();
        });
        rig.stepUntil("progress done", () -> !now().running);
        ChangeSetProgressDTO p = now();
        assertEquals("rejected-in-shadow", p.outcome);
        assertTrue(p.why.startsWith("update stage: rejected in shadow after 20 cycles: the new version (pid "
                + newHalf.pid + ") exited: killed by signal 11"), p.why);
        assertArrayEquals(new String[] {"checking", "preparing", "shadow", "done"}, p.phases);
        assertEntry(p.updates[0], "stage", "shadow", 20, 200, 0, "rejected-in-shadow");
        assertEquals(p.why, p.updates[0].why);
        assertFalse(phasesSeen().contains("switching"));
        assertFalse(phasesSeen().contains("window"));
    }

    @Test
    void aSetRefusedByTheCellEndsRefusedWithoutPreparing() throws Exception {
        runningCell();
        ChangeSet bad = ChangeSet.builder().install("nobody", Path.of("/x")).build();
        CompletableFuture<ChangeSetResult> f = actor.call(() -> cell.applyChangeSet(bad), 0);
        rig.stepUntil("the outcome", f::isDone);
        ChangeSetProgressDTO p = now();
        assertFalse(p.running);
        assertEquals("refused", p.outcome);
        assertTrue(p.why.contains("no component 'nobody' is known to the cell"), p.why);
        assertArrayEquals(new String[] {"checking", "done"}, p.phases);
        assertEquals(0, p.updates.length, "no update, refused before the executor took it");
    }

    /** src's update to 1.1.0 (new output {@code /arflex.t.1-src.out.y}), its shadow run and window. */
    private static final String OLD_SRC_Y = "/arflex.t.src.out.y";
    private static final String NEW_SRC_Y = "/arflex.t.1-src.out.y";

    @Test
    void eachUpdateOfASetShowsItsOwnCountersAndVerdictKeptAfterTheApply() throws Exception {
        runningCell();
        List<ChangeSet.Tolerance> y = List.of(new ChangeSet.Tolerance("y", "value", 0.01));
        ChangeSet set = ChangeSet.builder()
                .update("src", parse("src", "src", OUT, "1.1.0"), Path.of("/nonexistent/src-1.1"),
                        "file:/x/src-1.1.jar", 40, List.of(), 100, y)
                .update("stage", parse("stage", "stage", IN_SRC + OUT, "1.1.0"), Path.of("/nonexistent/stage-1.1"),
                        "file:/x/stage-1.1.jar", 50, List.of(), 200, y)
                .build();
        CompletableFuture<ChangeSetResult> f = actor.call(() -> cell.applyChangeSet(set), 0);
        rig.stepUntil("both new halves started in shadow", () -> {
            now();
            return fake.events.contains("1-src START") && fake.events.contains("1-stage START") || f.isDone();
        });
        assertFalse(f.isDone(), rig.log::toString);
        ChangeSetProgressDTO p = now();
        assertEquals("shadow", p.phase);
        assertEquals(2, p.updates.length, "one entry per update");
        // each shadow run said it began (cycle 0, nothing compared yet)
        assertEntry(p.updates[0], "src", "shadow", 0, 100, 0, null);
        assertEntry(p.updates[1], "stage", "shadow", 0, 200, 0, null);
        assertTrue(seen.stream().anyMatch(s -> s.updates.length == 2 && s.updates[0].phase == null
                && s.updates[1].phase == null), "neither in shadow while preparing");
        assertTrue(seen.stream().filter(s -> "preparing".equals(s.phase)).allMatch(s -> s.updates.length == 2),
                "the entries are there from the executor's acceptance on");
        FakeLauncher.FakeHalf newSrc = fake.running.get("1-src");
        FakeLauncher.FakeHalf newStage = fake.running.get("1-stage");
        fake.values.put(OLD_SRC_Y, sample(500, 7_000, 2.000));
        fake.values.put(NEW_SRC_Y, sample(3, 7_000, 2.002));
        fake.values.put(OLD_Y, sample(500, 7_000, 1.000));
        fake.values.put(NEW_Y, sample(3, 7_000, 1.004));
        // interleaved: src moves, then stage, then src again; each entry keeps its own counters
        newSrc.stats = cycles(30);
        look();
        p = now();
        assertEquals("src", p.component, "the fields above show the one that moved last");
        assertEntry(p.updates[0], "src", "shadow", 30, 100, 0.002, null);
        assertTrue(p.updates[0].step.startsWith("update src: shadow run of pid " + newSrc.pid + ", cycle 30 of 100"),
                p.updates[0].step);
        assertEntry(p.updates[1], "stage", "shadow", 0, 200, 0, null);
        newStage.stats = cycles(70);
        look();
        p = now();
        assertEquals("stage", p.component);
        assertEquals(70, p.cycle);
        assertEntry(p.updates[0], "src", "shadow", 30, 100, 0.002, null);
        assertEntry(p.updates[1], "stage", "shadow", 70, 200, 0.004, null);
        newSrc.stats = cycles(60);
        look();
        p = now();
        assertEquals("src", p.component);
        assertEntry(p.updates[0], "src", "shadow", 60, 100, 0.002, null);
        assertEntry(p.updates[1], "stage", "shadow", 70, 200, 0.004, null);
        // both pass: switched, then each its own window (src 40 cycles, stage 50)
        newSrc.stats = cycles(100);
        newStage.stats = cycles(200);
        look();
        rig.stepUntil("the switch", () -> {
            now();
            return f.isDone();
        });
        assertTrue(f.join().applied(), f.join().text());
        rig.stepUntil("both windows' baselines", () -> {
            ChangeSetProgressDTO n = now();
            return "window".equals(n.updates[0].phase) && n.updates[0].cycles == 40
                    && "window".equals(n.updates[1].phase) && n.updates[1].cycles == 50;
        });
        newSrc.stats = cycles(120);
        newStage.stats = cycles(230);
        look();
        p = now();
        assertEquals("window", p.phase);
        assertEntry(p.updates[0], "src", "window", 20, 40, 0.002, null);
        assertEntry(p.updates[1], "stage", "window", 30, 50, 0.004, null);
        assertTrue(p.updates[1].step.startsWith("update stage: rollback window, cycle 30 of 50 of pid " + newStage.pid),
                p.updates[1].step);
        // src's window is over: its verdict is in while stage's window goes on
        newSrc.stats = cycles(150);
        look();
        rig.stepUntil("src's verdict", () -> now().updates[0].verdict != null);
        p = now();
        assertTrue(p.running);
        assertEntry(p.updates[0], "src", "window", 50, 40, 0.002, "committed");
        assertTrue(p.updates[0].why.startsWith("update src: committed: the new version ran 50 cycles"),
                p.updates[0].why);
        assertEntry(p.updates[1], "stage", "window", 30, 50, 0.004, null);
        newStage.stats = cycles(260);
        look();
        rig.stepUntil("the set's outcome", () -> f.join().verdict().isDone() && !now().running);
        p = now();
        assertEquals("committed", p.outcome);
        // after the apply, each update's last counters and its verdict are kept
        assertEntry(p.updates[0], "src", "window", 50, 40, 0.002, "committed");
        assertEntry(p.updates[1], "stage", "window", 60, 50, 0.004, "committed");
        assertTrue(p.updates[1].why.startsWith("update stage: committed: the new version ran 60 cycles"),
                p.updates[1].why);
        // a reader's copy: changing it changes nothing shown
        p.updates[0].cycle = -1;
        p.updates[1] = null;
        assertEquals(50, now().updates[0].cycle);
        assertEquals("stage", now().updates[1].component);
    }

    @Test
    void whenOneUpdateOfASetIsRejectedInShadowTheOtherIsCancelledNamingItAndItsReason() throws Exception {
        runningCell();
        List<ChangeSet.Tolerance> y = List.of(new ChangeSet.Tolerance("y", "value", 0.01));
        ChangeSet set = ChangeSet.builder()
                .update("src", parse("src", "src", OUT, "1.1.0"), Path.of("/nonexistent/src-1.1"),
                        "file:/x/src-1.1.jar", 40, List.of(), 100, y)
                .update("stage", parse("stage", "stage", IN_SRC + OUT, "1.1.0"), Path.of("/nonexistent/stage-1.1"),
                        "file:/x/stage-1.1.jar", 50, List.of(), 200, y)
                .build();
        CompletableFuture<ChangeSetResult> f = actor.call(() -> cell.applyChangeSet(set), 0);
        rig.stepUntil("both new halves started in shadow", () -> {
            now();
            return fake.events.contains("1-src START") && fake.events.contains("1-stage START") || f.isDone();
        });
        FakeLauncher.FakeHalf newSrc = fake.running.get("1-src");
        FakeLauncher.FakeHalf newStage = fake.running.get("1-stage");
        newSrc.stats = cycles(25);
        newStage.stats = cycles(45);
        look();
        newStage.crash(139, "killed by signal 11");
        rig.stepUntil("the outcome", () -> {
            now();
            return f.isDone();
        });
        rig.stepUntil("progress done", () -> !now().running);
        ChangeSetProgressDTO p = now();
        assertEquals("rejected-in-shadow", p.outcome);
        // src's shadow run was cancelled for stage's rejection: it keeps its counters and says so (D62)
        assertEntry(p.updates[0], "src", "shadow", 25, 100, 0, "cancelled");
        assertEquals("cancelled: update stage was rejected in shadow (the new version (pid " + newStage.pid
                + ") exited: killed by signal 11)", p.updates[0].why);
        assertEntry(p.updates[1], "stage", "shadow", 45, 200, 0, "rejected-in-shadow");
        assertTrue(p.updates[1].why.startsWith("update stage: rejected in shadow after 45 cycles: the new version (pid "
                + newStage.pid + ") exited: killed by signal 11"), p.updates[1].why);
        assertEquals(p.why, p.updates[1].why);
    }

    /** D70: an update refused once its new half is READY cancels the set's other updates, as a rejection does. */
    @Test
    void everyOtherUpdateIsCancelledWhenOneIsRefusedBeforeItsShadowRun() {
        ChangeSetProgress progress = new ChangeSetProgress(() -> 1_000);
        ChangeSetProgress.Apply a = progress.begin(List.of("update a x", "update b y shadow 50"));
        a.claim(List.of("a", "b"));
        a.phase(ChangeSetProgress.PREPARING, "1 of 2 new RT halves READY");
        String why = "its new RT half (pid 7) registers no re-adopt hook (arflex_component_readopt), so ...";
        String refusal = "update b: refused: " + why + "; nothing changed (pid 3 runs b on)";
        a.refused("b", refusal, why);
        a.done(ChangeSetProgress.outcomeOf(false, refusal, null, false), refusal);
        ChangeSetProgressDTO p = progress.snapshot();
        assertEquals("refused", p.outcome);
        assertEquals(List.of("cancelled", "refused"), List.of(p.updates[0].verdict, p.updates[1].verdict));
        assertEquals("cancelled: update b was refused before its shadow run (" + why + ")", p.updates[0].why);
        assertEquals(refusal, p.updates[1].why);
        assertEquals(List.of(0L, 0L), List.of(p.updates[0].cycle, p.updates[1].cycle));
    }

    @Test
    void everyUpdateWithoutAVerdictOfItsOwnIsCancelledWhenAnotherIsRejectedInShadow() {
        ChangeSetProgress progress = new ChangeSetProgress(() -> 1_000);
        ChangeSetProgress.Apply a = progress.begin(List.of("update a x", "update b y", "update c z", "update d w"));
        a.claim(List.of("a", "b", "c", "d"));
        a.cycles(ChangeSetProgress.SHADOW, "a at 100 of 100", "a", 100, 100, null, 0, 0); // a passed, waits
        a.cycles(ChangeSetProgress.SHADOW, "b at 30 of 200", "b", 30, 200, null, 0, 0);
        a.cycles(ChangeSetProgress.SHADOW, "d at 10 of 50", "d", 10, 50, null, 0, 0); // c has no shadow run
        a.rejectedInShadow("b", "update b: rejected in shadow after 30 cycles: y.value 0.5 from the running "
                + "version's (tolerance 0.01); nothing changed (pid 9 runs b on)", "y.value 0.5 from the running "
                + "version's (tolerance 0.01)", 30);
        a.done(ChangeSetProgress.REJECTED_IN_SHADOW, "update b: rejected in shadow after 30 cycles: ...");
        UpdateProgressDTO[] u = progress.snapshot().updates;
        String cancelled = "cancelled: update b was rejected in shadow (y.value 0.5 from the running version's "
                + "(tolerance 0.01))";
        assertEquals(List.of("cancelled", "rejected-in-shadow", "cancelled", "cancelled"),
                List.of(u[0].verdict, u[1].verdict, u[2].verdict, u[3].verdict));
        assertEquals(List.of(cancelled, cancelled, cancelled), List.of(u[0].why, u[2].why, u[3].why));
        assertTrue(u[1].why.startsWith("update b: rejected in shadow after 30 cycles"), u[1].why);
        // each keeps its counters: a's passed run, b's 30, c none, d's 10 of 50
        assertEquals(List.of(100L, 30L, 0L, 10L), List.of(u[0].cycle, u[1].cycle, u[2].cycle, u[3].cycle));
        assertNull(u[2].phase);
        // the entries the history keeps are the same, and copies
        UpdateProgressDTO[] kept = a.updates();
        assertEquals(4, kept.length);
        assertEquals(cancelled, kept[3].why);
        kept[3].why = "changed by a reader";
        assertEquals(cancelled, a.updates()[3].why);
    }

    private static void assertEntry(UpdateProgressDTO u, String component, String phase, long cycle, long cycles,
                                    double worstDeviation, String verdict) {
        String s = component + " " + u.phase + " " + u.cycle + " of " + u.cycles + " worst " + u.worstField + " "
                + u.worstDeviation + " verdict " + u.verdict + ": " + u.step;
        assertEquals(component, u.component, s);
        assertEquals(phase, u.phase, s);
        assertEquals(cycle, u.cycle, s);
        assertEquals(cycles, u.cycles, s);
        assertEquals(worstDeviation, u.worstDeviation, 1e-9, s);
        // every update here compares y.value (tolerance 0.01): named from its shadow run's first look on
        assertEquals(phase == null ? null : "y.value", u.worstField, s);
        assertEquals(phase == null ? 0 : 0.01, u.tolerance, s);
        assertEquals(verdict, u.verdict, s);
    }

    @Test
    void theApplyShownIsTheFirstUntilTheExecutorTakesAnother() {
        AtomicLong clock = new AtomicLong(1_000);
        ChangeSetProgress progress = new ChangeSetProgress(clock::get);
        ChangeSetProgress.Apply a = progress.begin(List.of("install a"));
        clock.set(1_200);
        a.phase(ChangeSetProgress.PREPARING, "preparing a");
        ChangeSetProgress.Apply b = progress.begin(List.of("install b"));
        b.phase(ChangeSetProgress.CHECKING, "checking b");
        b.done("refused", "another change set is being applied");
        ChangeSetProgressDTO p = progress.snapshot();
        assertArrayEquals(new String[] {"install a"}, p.actions, "a second apply while one runs is not shown");
        assertEquals("preparing a", p.step);
        assertEquals(1_000, p.startedMillis);
        assertEquals(1_200, p.phaseMillis);
        // the executor accepted c (a's checking was not over yet): c is shown from now on, a no more
        ChangeSetProgress.Apply c = progress.begin(List.of("install c"));
        clock.set(1_500);
        c.claim(List.of());
        a.done("committed", null);
        p = progress.snapshot();
        assertArrayEquals(new String[] {"install c"}, p.actions);
        assertArrayEquals(new String[] {"checking"}, p.phases);
        assertEquals(1_500, p.startedMillis);
        assertTrue(p.running);
        c.done("torn-down", "preparation failed, nothing changed: x");
        p = progress.snapshot();
        assertFalse(p.running);
        assertEquals("torn-down", p.outcome);
        // once over, the next apply is shown from its beginning
        ChangeSetProgress.Apply d = progress.begin(List.of("install d"));
        assertArrayEquals(new String[] {"install d"}, progress.snapshot().actions);
        assertTrue(d.shown());
    }

    @Test
    void theOutcomeIsNamedAsTheConsoleNamesIt() {
        assertEquals("rejected-in-shadow", ChangeSetProgress.outcomeOf(false,
                "update s: rejected in shadow after 5 cycles: why; nothing changed", null, false));
        assertEquals("torn-down", ChangeSetProgress.outcomeOf(false, "preparation failed, nothing changed: x", null, false));
        assertEquals("torn-down", ChangeSetProgress.outcomeOf(false, "the cell changed while the set was prepared: x",
                null, false));
        assertEquals("refused", ChangeSetProgress.outcomeOf(false, "install x: no component", null, false));
        assertEquals("committed", ChangeSetProgress.outcomeOf(true, null, null, false));
        assertEquals("committed", ChangeSetProgress.outcomeOf(true, null, "update s: passed its shadow run of 3 cycles\n"
                + "update s: committed: the new version ran 9 cycles", false));
        assertEquals("rolled-back", ChangeSetProgress.outcomeOf(true, null, "update s: rolled back after 12 cycles of "
                + "the new version (file:/x.jar): why; pid 4 runs it again", false));
        assertEquals("applied", ChangeSetProgress.outcomeOf(true, null, null, true));
    }
}
