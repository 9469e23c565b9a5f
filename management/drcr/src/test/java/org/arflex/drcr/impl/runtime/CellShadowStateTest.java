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
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.List;
import java.util.concurrent.CompletableFuture;
import org.arflex.drcr.impl.lifecycle.State;
import org.junit.jupiter.api.AfterEach;
import org.junit.jupiter.api.Test;

/**
 * D61: the state of an update's shadow half. It is told the running half's state segment
 * (ADOPT) after READY and adopts it at its START, which is the shadow run's; at the switch,
 * before its consumers follow it, it takes the running half's newest state again (READOPT), so
 * the motion goes on from the old half's state at the switch. A re-adopt it cannot take hands the
 * component back to the old half (D55), the verdict saying why. Steppable actor, fake halves.
 */
class CellShadowStateTest {

    private static final String TRAJ = "<state type=\"arflex.TrajectoryState\" typeVersion=\"1.0\"/>";

    private final UpdateRig rig = new UpdateRig();
    private final FakeLauncher fake = rig.fake;
    private final Cell cell = rig.cell;

    @AfterEach
    void nothingLeaks() {
        rig.close();
    }

    private CompletableFuture<ChangeSetResult> intoShadow(String state) throws Exception {
        rig.runningCell("50us", state);
        return rig.applyIntoShadow(UpdateRig.update(parse("stage", "stage", IN_SRC + OUT, "1.1.0", state), 50, 100,
                List.of(new ChangeSet.Tolerance("y", "value", 0.01))), () -> { });
    }

    /** Passes the shadow run (100 cycles, one value of the same source cycle compared) and steps to the switch. */
    private ChangeSetResult pass(CompletableFuture<ChangeSetResult> f) {
        fake.values.put(OLD_Y, sample(500, 7_000, 1.000));
        fake.values.put(NEW_Y, sample(3, 7_000, 1.004));
        fake.running.get("1-stage").stats = cycles(100, 0);
        rig.look();
        rig.stepUntil("the switch", f::isDone);
        return f.join();
    }

    @Test
    void theShadowHalfStartsFromTheRunningStateAndTakesItAgainBeforeItsConsumersMove() throws Exception {
        CompletableFuture<ChangeSetResult> f = intoShadow(TRAJ);
        // its START, the shadow run's, is where it adopts: after the ADOPT, before any cycle
        int adopt = rig.index("1-stage ADOPT /arflex.t.stage.state");
        int started = rig.index("1-stage START");
        assertTrue(adopt < started, fake.events::toString);
        assertFalse(fake.events.stream().anyMatch(e -> e.contains("READOPT")), "no re-adopt in shadow: " + fake.events);
        int mark = fake.events.size();
        ChangeSetResult r = pass(f);
        assertTrue(r.applied(), r.text());
        List<String> sw = rig.since(mark);
        int readopt = sw.indexOf("1-stage READOPT /arflex.t.stage.state");
        int moved = sw.indexOf("user BIND x " + NEW_Y);
        assertTrue(readopt >= 0 && readopt < moved, "the re-adopt before the consumer's BIND: " + sw);
        assertEquals(1, sw.stream().filter(e -> e.startsWith("1-stage ")).count(), "only the re-adopt: " + sw);
        assertTrue(rig.log.stream().anyMatch(l -> l.contains("stage: the shadow half (pid " + fake.running.get("1-stage").pid
                + ") re-adopted /arflex.t.stage.state at the switch")), rig.log::toString);
        fake.running.get("1-stage").stats = cycles(160, 0);
        rig.look();
        rig.stepUntil("the verdict", () -> r.verdict().isDone());
        assertTrue(r.verdict().join().contains("update stage: committed"), r.verdict().join());
    }

    @Test
    void aShadowHalfThatCannotTakeTheStateAtTheSwitchHandsBackToTheOldHalf() throws Exception {
        CompletableFuture<ChangeSetResult> f = intoShadow(TRAJ);
        FakeLauncher.FakeHalf oldHalf = fake.running.get("stage");
        fake.refuseReadopt.put("1-stage", "READOPT of /arflex.t.stage.state refused by 1-stage: status -95 "
                + "(EOPNOTSUPP: its executable has no re-adopt hook, arflex_component_readopt)");
        int mark = fake.events.size();
        ChangeSetResult r = pass(f);
        assertTrue(r.applied(), r.text());
        rig.stepUntil("the verdict", () -> r.verdict().isDone());
        String v = r.verdict().join();
        assertTrue(v.contains("update stage: rolled back at the switch: its shadow half could not take the running "
                + "half's state at the switch: READOPT of /arflex.t.stage.state refused by 1-stage: status -95 "
                + "(EOPNOTSUPP: its executable has no re-adopt hook, arflex_component_readopt); pid " + oldHalf.pid
                + " (stage) runs it again"), v);
        assertEquals(oldHalf.pid, cell.instance("stage").orElseThrow().half.pid());
        assertEquals("1.0.0", cell.instance("stage").orElseThrow().contract().version().toString());
        assertEquals(State.ACTIVE, rig.state("stage"));
        assertFalse(cell.instance("stage").orElseThrow().awaitingReset, "nothing waits for a reset");
        rig.stepUntil("the shadow half stopped and its segments gone", () -> !fake.running.containsKey("1-stage")
                && !fake.openOutputs.containsKey("/arflex.t.1-stage.out.y")
                && !fake.openOutputs.containsKey("/arflex.t.1-stage.state"));
        List<String> after = rig.since(mark);
        assertFalse(after.contains("user BIND x " + NEW_Y), "the consumer never moved: " + after);
        assertFalse(after.contains("stage SHUTDOWN"), "the old half runs on: " + after);
        assertTrue(fake.openOutputs.containsKey("/arflex.t.stage.state"), "the old half keeps its state segment");
    }

    /**
     * D70: a new half that registers no re-adopt hook could not take the running half's state at
     * the switch; its update is refused once it is READY, before its shadow run's START, the verdict
     * naming the component, the reason and what to do. Nothing that ran is touched.
     */
    @Test
    void aShadowedUpdateWhoseNewHalfCannotReadoptIsRefusedOnceReadyBeforeItsShadowRun() throws Exception {
        rig.runningCell("50us", TRAJ);
        FakeLauncher.FakeHalf oldHalf = fake.running.get("stage");
        String bindingsBefore = fake.events.stream().filter(e -> e.startsWith("user ")).toList().toString();
        fake.noReadoptHook.add("1-stage");
        int mark = fake.events.size();
        CompletableFuture<ChangeSetResult> f = rig.actor.call(() -> cell.applyChangeSet(UpdateRig.update(
                parse("stage", "stage", IN_SRC + OUT, "1.1.0", TRAJ), 50, 100,
                List.of(new ChangeSet.Tolerance("y", "value", 0.01)))), 0);
        rig.stepUntil("the outcome", f::isDone);
        ChangeSetResult r = f.join();
        assertFalse(r.applied(), r.text());
        List<String> ev = rig.since(mark);
        java.util.regex.Matcher pid = java.util.regex.Pattern.compile("its new RT half \\(pid (\\d+)\\)").matcher(r.refusal());
        assertTrue(pid.find() && ev.contains("1-stage LAUNCH"), r.refusal() + " " + ev);
        long newPid = Long.parseLong(pid.group(1));
        assertTrue(newPid != oldHalf.pid, r.refusal());
        assertEquals("update stage: refused: its new RT half (pid " + newPid + ") registers no re-adopt hook "
                + "(arflex_component_readopt), so it cannot take the running half's state block arflex.TrajectoryState "
                + "1.0 again at the switch of a shadow run; apply it without a shadow run (shadow 0; the new half then "
                + "adopts the state at its START), or give its RT half a re-adopt hook; nothing changed (pid " + oldHalf.pid
                + " runs stage on)", r.refusal());
        // known at READY: never started, never re-adopted, never compared
        assertFalse(ev.contains("1-stage START"), ev::toString);
        assertTrue(ev.stream().noneMatch(e -> e.contains("READOPT")), ev::toString);
        assertTrue(rig.log.stream().noneMatch(l -> l.contains("runs in shadow")), rig.log::toString);
        // the old half keeps the component, nothing waits for a reset, no consumer moved
        assertEquals(oldHalf.pid, cell.instance("stage").orElseThrow().half.pid());
        assertEquals("1.0.0", cell.instance("stage").orElseThrow().contract().version().toString());
        assertEquals(State.ACTIVE, rig.state("stage"));
        assertFalse(cell.instance("stage").orElseThrow().awaitingReset, "nothing waits for a reset");
        assertFalse(ev.stream().anyMatch(e -> e.startsWith("stage ")), "the old half untouched: " + ev);
        assertEquals(bindingsBefore, fake.events.stream().filter(e -> e.startsWith("user ")).toList().toString());
        rig.stepUntil("the refused half stopped and its segments gone", () -> !fake.running.containsKey("1-stage")
                && !fake.openOutputs.containsKey(NEW_Y) && !fake.openOutputs.containsKey("/arflex.t.1-stage.state"));
        assertTrue(fake.openOutputs.containsKey("/arflex.t.stage.state"), "the old half keeps its state segment");
        // the progress and the history: the set refused, its update's entry says why
        rig.stepUntil("the progress done", () -> !cell.changeSetProgress().snapshot().running);
        var p = cell.changeSetProgress().snapshot();
        assertEquals("refused", p.outcome);
        assertEquals(r.refusal(), p.why);
        assertEquals("refused", p.updates[0].verdict);
        assertEquals(r.refusal(), p.updates[0].why);
    }

    /** D70: the same new half without a shadow run needs no re-adopt: it adopts at its START and commits. */
    @Test
    void theSameUpdateWithoutAShadowRunIsApplied() throws Exception {
        rig.runningCell("50us", TRAJ);
        fake.noReadoptHook.add("1-stage");
        CompletableFuture<ChangeSetResult> f = rig.actor.call(() -> cell.applyChangeSet(UpdateRig.update(
                parse("stage", "stage", IN_SRC + OUT, "1.1.0", TRAJ), 50, 0, List.of())), 0);
        rig.stepUntil("the switch", f::isDone);
        ChangeSetResult r = f.join();
        assertTrue(r.applied(), r.text());
        assertTrue(fake.events.contains("1-stage ADOPT /arflex.t.stage.state"), fake.events::toString);
        fake.running.get("1-stage").stats = cycles(60, 0);
        rig.look();
        rig.stepUntil("the verdict", () -> r.verdict().isDone());
        assertTrue(r.verdict().join().contains("update stage: committed"), r.verdict().join());
    }

    @Test
    void aShadowRunWithoutAStateBlockHasNothingToReadopt() throws Exception {
        fake.noReadoptHook.add("1-stage"); // D70: and so needs no re-adopt hook
        CompletableFuture<ChangeSetResult> f = intoShadow("");
        ChangeSetResult r = pass(f);
        assertTrue(r.applied(), r.text());
        assertTrue(fake.events.stream().noneMatch(e -> e.contains("ADOPT")), fake.events::toString);
        fake.running.get("1-stage").stats = cycles(160, 0);
        rig.look();
        rig.stepUntil("the verdict", () -> r.verdict().isDone());
    }
}
