package org.arflex.drcr.impl.runtime;

import static org.arflex.drcr.impl.runtime.UpdateRig.IN_SRC;
import static org.arflex.drcr.impl.runtime.UpdateRig.NEW_Y;
import static org.arflex.drcr.impl.runtime.UpdateRig.OLD_Y;
import static org.arflex.drcr.impl.runtime.UpdateRig.OUT;
import static org.arflex.drcr.impl.runtime.UpdateRig.cycles;
import static org.arflex.drcr.impl.runtime.UpdateRig.parse;
import static org.arflex.drcr.impl.runtime.UpdateRig.sample;
import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertNotNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.file.Path;
import java.util.List;
import java.util.Set;
import java.util.concurrent.CompletableFuture;
import org.arflex.contract.Contract;
import org.arflex.drcr.impl.lifecycle.ManualActor;
import org.junit.jupiter.api.AfterEach;
import org.junit.jupiter.api.Test;

/**
 * The shadow run of an update (D42): the new version's half is bound to the running version's
 * providers and started, but no consumer is bound to it, for {@code shadow} of its cycles; its
 * exit, extra overruns, or an output that differs from the running version's beyond a tolerance
 * reject the update with the consumers never touched and the old half running on; passing, the
 * switch is as without a shadow run (no second BIND or START of the new half) and the window
 * follows. Steppable actor, fake halves whose counters and output values the test sets.
 *
 * <p>The cell of {@link CellUpdateSetTest}: {@code src} -> {@code stage} -> {@code user}.
 */
class CellShadowRunTest {

    private final UpdateRig rig = new UpdateRig();
    private final FakeLauncher fake = rig.fake;
    private final ManualActor actor = rig.actor;
    private final Cell cell = rig.cell;

    @AfterEach
    void nothingLeaks() {
        rig.close();
    }

    private ChangeSet update(long shadow, long window, List<ChangeSet.Tolerance> tolerances) throws Exception {
        return UpdateRig.update(parse("stage", "stage", IN_SRC + OUT, "1.1.0", ""), window, shadow, tolerances);
    }

    /** Applies {@code set} and steps until the shadow run has begun (the new half STARTed). */
    private CompletableFuture<ChangeSetResult> applyIntoShadow(ChangeSet set) {
        return rig.applyIntoShadow(set, () -> { });
    }

    @Test
    void aVersionThatPassesItsShadowRunIsSwitchedWithoutASecondStartAndKeptInItsWindow() throws Exception {
        rig.boundCell();
        FakeLauncher.FakeHalf oldHalf = fake.running.get("stage");
        CompletableFuture<ChangeSetResult> f = applyIntoShadow(update(100, 50,
                List.of(new ChangeSet.Tolerance("y", "value", 0.01))));
        assertFalse(f.isDone(), "switched before its shadow run: " + rig.log);
        // in shadow: bound to the running version's provider and started, its consumer untouched
        assertTrue(fake.events.indexOf("1-stage BIND x /arflex.t.src.out.y") < fake.events.indexOf("1-stage START"),
                fake.events::toString);
        assertFalse(fake.events.contains("user BIND x " + NEW_Y), fake.events::toString);
        assertEquals(oldHalf.pid, cell.instance("stage").orElseThrow().half.pid(), "the running version is the component's");
        assertEquals("1.0.0", cell.instance("stage").orElseThrow().contract().version());
        FakeLauncher.FakeHalf newHalf = fake.running.get("1-stage");
        fake.values.put(OLD_Y, sample(500, 7_000, 1.000));
        fake.values.put(NEW_Y, sample(3, 7_000, 1.004));
        newHalf.stats = cycles(40, 0);
        rig.look();
        assertFalse(f.isDone(), "40 of 100 cycles");
        assertFalse(fake.events.contains("user BIND x " + NEW_Y));
        // a value of another source cycle is not compared (it differs by more than the tolerance)
        fake.values.put(NEW_Y, sample(4, 8_000, 1.5));
        newHalf.stats = cycles(100, 0);
        int mark = fake.events.size();
        rig.look();
        rig.stepUntil("the switch", f::isDone);
        ChangeSetResult r = f.join();
        assertTrue(r.applied(), r.text());
        // the switch: the consumer's BIND, and no second BIND or START of the new half
        assertTrue(rig.since(mark).contains("user BIND x " + NEW_Y), fake.events::toString);
        assertFalse(rig.since(mark).stream().anyMatch(e -> e.startsWith("1-stage ")), fake.events::toString);
        assertEquals(newHalf.pid, cell.instance("stage").orElseThrow().half.pid());
        // then the window, as without a shadow run
        newHalf.stats = cycles(160, 0);
        rig.look();
        rig.stepUntil("the verdict", () -> r.verdict().isDone());
        String v = r.verdict().join();
        assertTrue(v.startsWith("update stage: passed its shadow run of 100 cycles (0 cycles late, the "
                + "running version 0; 1 values compared, y.value at most 0.00400 from the running version's (tolerance "
                + "0.01))\nupdate stage: committed: the new version ran 60 cycles"), v);
        rig.stepUntil("the old half stopped", () -> !fake.running.containsKey("stage")
                && !fake.openOutputs.containsKey(OLD_Y));
        assertTrue(oldHalf.cleaned);
    }

    @Test
    void aVersionThatCrashesInShadowIsRejectedAndItsConsumersAreNeverRebound() throws Exception {
        rig.boundCell();
        FakeLauncher.FakeHalf oldHalf = fake.running.get("stage");
        FakeLauncher.FakeHalf src = fake.running.get("src");
        FakeLauncher.FakeHalf user = fake.running.get("user");
        Contract before = cell.instance("stage").orElseThrow().contract();
        CompletableFuture<ChangeSetResult> f = applyIntoShadow(update(200, 1000, List.of()));
        FakeLauncher.FakeHalf newHalf = fake.running.get("1-stage");
        newHalf.stats = cycles(50, 0);
        rig.look();
        newHalf.crash(139, "killed by signal 11");
        rig.stepUntil("the outcome", f::isDone);
        ChangeSetResult r = f.join();
        assertFalse(r.applied(), r.text());
        assertEquals("update stage: rejected in shadow after 50 cycles: the new version (pid " + newHalf.pid
                + ") exited: killed by signal 11; nothing changed (pid " + oldHalf.pid + " runs stage on)", r.refusal());
        // nothing else changed: no consumer rebound, no reset, no restart, the same halves and contract
        assertTrue(fake.events.stream().noneMatch(e -> e.startsWith("user BIND x /arflex.t.1-stage")
                || e.startsWith("user UNBIND") || e.endsWith(" RESET")), fake.events::toString);
        assertTrue(fake.events.stream().noneMatch(e -> e.equals("stage SHUTDOWN") || e.equals("user SHUTDOWN")
                || e.equals("src SHUTDOWN")), fake.events::toString);
        assertEquals(oldHalf, fake.running.get("stage"));
        assertEquals(src, fake.running.get("src"));
        assertEquals(user, fake.running.get("user"));
        assertEquals(oldHalf.pid, cell.instance("stage").orElseThrow().half.pid());
        assertEquals(before, cell.instance("stage").orElseThrow().contract());
        assertEquals(0, cell.instance("stage").orElseThrow().restarts);
        assertEquals(Set.of("src", "stage", "user"), cell.planner().active());
        rig.stepUntil("the new segment gone", () -> !fake.openOutputs.containsKey(NEW_Y));
        // the next set may go
        ChangeSetResult again = actor.call(() -> cell.planChangeSet(update(10, 10, List.of())), 0);
        assertTrue(again.admitted(), again.text());
    }

    @Test
    void anOutputBeyondItsToleranceRejectsTheUpdateNamingIt() throws Exception {
        rig.boundCell();
        FakeLauncher.FakeHalf oldHalf = fake.running.get("stage");
        CompletableFuture<ChangeSetResult> f = applyIntoShadow(update(200, 1000,
                List.of(new ChangeSet.Tolerance("y", "value", 0.01))));
        FakeLauncher.FakeHalf newHalf = fake.running.get("1-stage");
        fake.values.put(OLD_Y, sample(900, 42_000, 2.0));
        fake.values.put(NEW_Y, sample(30, 42_000, 2.5));
        newHalf.stats = cycles(30, 0);
        rig.look();
        rig.stepUntil("the outcome", f::isDone);
        ChangeSetResult r = f.join();
        assertFalse(r.applied(), r.text());
        assertEquals("update stage: rejected in shadow after 30 cycles: output y.value = 2.5 differs from the running "
                + "version's 2.0 by 0.500 (the same source cycle, t_ns 42000), beyond its tolerance 0.01; nothing "
                + "changed (pid " + oldHalf.pid + " runs stage on)", r.refusal());
        assertFalse(fake.events.contains("user BIND x " + NEW_Y), fake.events::toString);
        rig.stepUntil("the new half stopped and its segment gone", () -> !fake.running.containsKey("1-stage")
                && !fake.openOutputs.containsKey(NEW_Y));
        assertTrue(fake.events.contains("1-stage SHUTDOWN"), fake.events::toString);
        assertEquals(oldHalf.pid, cell.instance("stage").orElseThrow().half.pid());
    }

    @Test
    void extraOverrunsInShadowRejectTheUpdate() throws Exception {
        rig.boundCell();
        FakeLauncher.FakeHalf oldHalf = fake.running.get("stage");
        oldHalf.stats = cycles(9000, 4);
        CompletableFuture<ChangeSetResult> f = applyIntoShadow(update(200, 1000, List.of()));
        FakeLauncher.FakeHalf newHalf = fake.running.get("1-stage");
        newHalf.stats = cycles(20, 0);
        rig.look();
        // one more for the running version in the same time, in a look without one of the new
        // half's (D73: one in the same look as the new half's may be the new half's doing)
        oldHalf.stats = cycles(9050, 5);
        newHalf.stats = cycles(50, 0);
        rig.look();
        newHalf.stats = cycles(80, 1 + 1 + ChangeSetExecutor.OVERRUN_ALLOWANCE);
        rig.look();
        rig.stepUntil("the outcome", f::isDone);
        ChangeSetResult r = f.join();
        assertEquals("update stage: rejected in shadow after 80 cycles: it overran or missed its deadline in "
                + (2 + ChangeSetExecutor.OVERRUN_ALLOWANCE) + " of its 80 cycles (the running version, on the same "
                + "inputs: 1; allowed " + ChangeSetExecutor.OVERRUN_ALLOWANCE + " more); nothing changed (pid "
                + oldHalf.pid + " runs stage on)", r.refusal());
        assertFalse(fake.events.contains("user BIND x " + NEW_Y), fake.events::toString);
        rig.stepUntil("the new half stopped", () -> !fake.running.containsKey("1-stage"));
    }

    /** D73: in shadow too, a cycle that overran and missed its deadline counts once. */
    @Test
    void inShadowALateCycleCountsOnceAndAThirdBeyondTheRunningVersionRejects() throws Exception {
        rig.boundCell();
        FakeLauncher.FakeHalf oldHalf = fake.running.get("stage");
        oldHalf.stats = UpdateRig.late(9000, 4);
        CompletableFuture<ChangeSetResult> f = applyIntoShadow(update(200, 1000, List.of()));
        FakeLauncher.FakeHalf newHalf = fake.running.get("1-stage");
        newHalf.stats = UpdateRig.late(20, 0);
        rig.look();
        oldHalf.stats = UpdateRig.late(9100, 4);
        newHalf.stats = UpdateRig.late(100, ChangeSetExecutor.OVERRUN_ALLOWANCE);
        rig.look();
        assertFalse(f.isDone(), () -> "rejected: " + f.join().text());
        newHalf.stats = UpdateRig.late(120, ChangeSetExecutor.OVERRUN_ALLOWANCE + 1);
        rig.look();
        rig.stepUntil("the outcome", f::isDone);
        assertEquals("update stage: rejected in shadow after 120 cycles: it overran or missed its deadline in "
                + (ChangeSetExecutor.OVERRUN_ALLOWANCE + 1) + " of its 120 cycles (the running version, on the same "
                + "inputs: 0; allowed " + ChangeSetExecutor.OVERRUN_ALLOWANCE + " more); nothing changed (pid "
                + oldHalf.pid + " runs stage on)", f.join().refusal());
        rig.stepUntil("the new half stopped", () -> !fake.running.containsKey("1-stage"));
    }

    @Test
    void theContractDeclaresTheShadowRunAndTheCommandLineOverridesIt() throws Exception {
        Contract c = parse("stage", "stage", IN_SRC + OUT, "1.1.0", "<rollout shadow=\"300\" window=\"700\">"
                + "<tolerance port=\"y\" field=\"value\" abs=\"0.5\"/><envelope port=\"y\" field=\"value\" min=\"-9\" "
                + "max=\"9\"/></rollout>");
        ChangeSet.Update declared = ChangeSet.rules("stage", c, Path.of("/x"), "file:/x.jar", null, null, List.of(),
                List.of(), 1000);
        assertEquals(300, declared.shadow());
        assertEquals(700, declared.window());
        assertEquals(List.of(new ChangeSet.Tolerance("y", "value", 0.5)), declared.tolerances());
        assertEquals(List.of(new ChangeSet.Envelope("y", "value", -9, 9)), declared.envelopes());
        ChangeSet.Update given = ChangeSet.rules("stage", c, Path.of("/x"), "file:/x.jar", 50L, 20L,
                List.of(new ChangeSet.Envelope("y", "value", 0, 1)), List.of(new ChangeSet.Tolerance("y", "value", 0.1)),
                1000);
        assertEquals(20, given.shadow());
        assertEquals(50, given.window());
        assertEquals(List.of(new ChangeSet.Tolerance("y", "value", 0.1)), given.tolerances());
        assertEquals(List.of(new ChangeSet.Envelope("y", "value", 0, 1)), given.envelopes());
        ChangeSet.Update none = ChangeSet.rules("stage", parse("stage", "stage", IN_SRC + OUT, "1.1.0", ""),
                Path.of("/x"), "file:/x.jar", null, null, List.of(), List.of(), 1000);
        assertEquals(0, none.shadow());
        assertEquals(1000, none.window());
    }

    @Test
    void aToleranceOnAnUnknownOutputOrFieldOrWithoutAShadowRunIsRefused() throws Exception {
        rig.boundCell();
        int before = fake.events.size();
        ChangeSetResult port = actor.call(() -> cell.planChangeSet(update(10, 10,
                List.of(new ChangeSet.Tolerance("z", "value", 1)))), 0);
        assertTrue(port.refusal().startsWith("update stage file:/x/stage-1.1.jar: tolerance z.value +-1.0: the new "
                + "version has no output 'z'"), port.text());
        ChangeSetResult field = actor.call(() -> cell.planChangeSet(update(10, 10,
                List.of(new ChangeSet.Tolerance("y", "q", 1)))), 0);
        assertTrue(field.refusal().startsWith("update stage file:/x/stage-1.1.jar: tolerance y.q +-1.0: port type "
                + "arflex.Sample has no field 'q'"), field.text());
        ChangeSetResult noShadow = actor.call(() -> cell.planChangeSet(update(0, 10,
                List.of(new ChangeSet.Tolerance("y", "value", 1)))), 0);
        assertTrue(noShadow.refusal().contains("tolerances compare a shadow run, and none is declared"), noShadow.text());
        assertEquals(before, fake.events.size(), fake.events::toString);
        assertNotNull(cell.instance("stage").orElseThrow().half);
    }

    @Test
    void aVersionThatStopsCyclingInShadowIsRejectedAfterItsHeartbeatTimeout() throws Exception {
        rig.boundCell();
        CompletableFuture<ChangeSetResult> f = applyIntoShadow(update(200, 1000, List.of()));
        FakeLauncher.FakeHalf newHalf = fake.running.get("1-stage");
        newHalf.stats = cycles(10, 0);
        rig.look();
        for (int i = 0; i < 9; i++) { // 90 ms without a cycle: the contracts' heartbeat timeout is 100 ms
            rig.look();
        }
        assertFalse(f.isDone(), "rejected before its heartbeat timeout: " + rig.log);
        rig.look();
        rig.stepUntil("the outcome", f::isDone);
        assertTrue(f.join().refusal().startsWith("update stage: rejected in shadow after 10 cycles: it ran no cycle for "
                + "100 ms (heartbeat timeout 100 ms); nothing changed"), f.join().text());
        rig.stepUntil("the new half stopped", () -> !fake.running.containsKey("1-stage"));
        assertFalse(fake.events.contains("user BIND x " + NEW_Y), fake.events::toString);
    }

    @Test
    void aVersionTooSlowForItsShadowCyclesIsRejectedAfterFourTimesTheirPeriodsAndASecond() throws Exception {
        rig.boundCell();
        CompletableFuture<ChangeSetResult> f = applyIntoShadow(update(200, 1000, List.of()));
        FakeLauncher.FakeHalf newHalf = fake.running.get("1-stage");
        // one cycle per look (10 ms): 200 cycles of 1 ms would take 2 s; the limit is 4 x 200 ms + 1 s
        for (int i = 1; i < 180; i++) {
            newHalf.stats = cycles(i, 0);
            rig.look();
        }
        assertFalse(f.isDone(), "rejected before its time: " + rig.log);
        newHalf.stats = cycles(180, 0);
        rig.look();
        rig.stepUntil("the outcome", f::isDone);
        assertTrue(f.join().refusal().startsWith("update stage: rejected in shadow after 180 cycles: it ran only 180 of "
                + "its 200 shadow cycles in 1800 ms; nothing changed"), f.join().text());
    }

    @Test
    void toleranceWithoutAnyValueOfTheSameSourceCycleFailsClosed() throws Exception {
        rig.boundCell();
        CompletableFuture<ChangeSetResult> f = applyIntoShadow(update(100, 1000,
                List.of(new ChangeSet.Tolerance("y", "value", 0.01))));
        FakeLauncher.FakeHalf newHalf = fake.running.get("1-stage");
        fake.values.put(OLD_Y, sample(500, 7_000, 1.0));
        fake.values.put(NEW_Y, sample(3, 9_000, 1.0)); // always another source cycle
        newHalf.stats = cycles(100, 0);
        rig.look();
        rig.stepUntil("the outcome", f::isDone);
        assertEquals("update stage: rejected in shadow after 100 cycles: no value of the same source cycle of both "
                + "versions could be compared in 100 cycles (tolerances [y.value +-0.01]); nothing changed (pid "
                + fake.running.get("stage").pid + " runs stage on)", f.join().refusal());
    }
}
