package org.arflex.drcr.impl.runtime;

import static org.arflex.drcr.impl.runtime.UpdateRig.IN_SRC;
import static org.arflex.drcr.impl.runtime.UpdateRig.IN_STAGE;
import static org.arflex.drcr.impl.runtime.UpdateRig.OUT;
import static org.arflex.drcr.impl.runtime.UpdateRig.parse;
import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.file.Path;
import java.util.List;
import org.arflex.contract.Contract;
import org.arflex.contract.ContractParser;
import org.arflex.contract.PortTypes;
import org.arflex.drcr.impl.abi.ControlBlock;
import org.arflex.drcr.impl.lifecycle.State;
import org.junit.jupiter.api.AfterEach;
import org.junit.jupiter.api.Test;

/**
 * State transfer in a change set's update (D41): a contract's state block has a segment beside
 * the half's outputs; the new version is told the old half's segment (ADOPT) after READY and
 * before START; a new version that does not adopt the running one's state block is refused by
 * the plan naming both, before anything is launched; a refused ADOPT tears the set down; a
 * rollback hands nothing back (the old half never stopped). Steppable actor, fake halves.
 */
class CellStateTransferTest {

    private static final String TRAJ = "<state type=\"arflex.TrajectoryState\" typeVersion=\"1.0\"/>";
    private static final String TCP = "<state type=\"arflex.TcpCorrectionState\" typeVersion=\"1.0\"/>";
    private static final String TCP_FROM_TRAJ = "<state type=\"arflex.TcpCorrectionState\" typeVersion=\"1.0\">"
            + "<convertsFrom type=\"arflex.TrajectoryState\" typeVersion=\"1.0\"/></state>";

    private final UpdateRig rig = new UpdateRig();
    private final FakeLauncher fake = rig.fake;
    private final Cell cell = rig.cell;

    @AfterEach
    void nothingLeaks() {
        rig.close(); // fails on any half or segment (state segments included) left behind
    }

    private void runningCell(String stageState) throws Exception {
        rig.runningCell("50us", stageState);
    }

    private ChangeSet update(String state) throws Exception {
        return UpdateRig.update(parse("stage", "stage", IN_SRC + OUT, "1.1.0", state), 100, 0, List.of());
    }

    @Test
    void theNewVersionIsToldTheOldHalfsStateSegmentBeforeItsStart() throws Exception {
        runningCell(TRAJ);
        assertTrue(fake.openOutputs.containsKey("/arflex.t.stage.state"), fake.openOutputs::toString);
        assertTrue(fake.events.stream().anyMatch(e -> e.startsWith("CREATE /arflex.t.stage.state arflex.TrajectoryState ")),
                fake.events::toString);
        ChangeSetResult r = rig.apply(update(TRAJ));
        assertTrue(r.applied(), r.text());
        int launched = rig.index("1-stage LAUNCH");
        int adopt = rig.index("1-stage ADOPT /arflex.t.stage.state");
        int started = rig.index("1-stage START");
        int moved = rig.index("user BIND x /arflex.t.1-stage.out.y");
        assertTrue(launched < adopt && adopt < started && started < moved, fake.events.toString());
        assertTrue(fake.openOutputs.containsKey("/arflex.t.1-stage.state"), "the new half publishes its own");
        assertTrue(fake.openOutputs.containsKey("/arflex.t.stage.state"), "the old half still publishes in the window");
        fake.running.get("1-stage").stats = new ControlBlock.Stats(100, 0, 0, 0, 0, 0, 0, 0, 0, 0);
        rig.look();
        rig.stepUntil("the verdict", () -> r.verdict().isDone());
        assertTrue(r.verdict().join().startsWith("update stage: committed"), r.verdict().join());
        rig.stepUntil("the old state segment gone with the old half", () -> !fake.running.containsKey("stage")
                && !fake.openOutputs.containsKey("/arflex.t.stage.state"));
    }

    @Test
    void aDeclaredConversionIsAdmittedAndAdopts() throws Exception {
        runningCell(TRAJ);
        ChangeSetResult r = rig.apply(update(TCP_FROM_TRAJ));
        assertTrue(r.applied(), r.text());
        rig.index("1-stage ADOPT /arflex.t.stage.state");
        fake.running.get("1-stage").stats = new ControlBlock.Stats(100, 0, 0, 0, 0, 0, 0, 0, 0, 0);
        rig.look();
        rig.stepUntil("the verdict", () -> r.verdict().isDone());
    }

    @Test
    void aNewVersionWithAnotherStateTypeOrNoneIsRefusedByThePlanNamingBoth() throws Exception {
        runningCell(TRAJ);
        int before = fake.events.size();
        ChangeSetResult other = rig.apply(update(TCP));
        assertFalse(other.applied());
        assertTrue(other.refusal().contains("update stage file:/x/stage-1.1.jar: state block: the running version 1.0.0 "
                + "hands over arflex.TrajectoryState 1.0, the new version 1.1.0 takes arflex.TcpCorrectionState 1.0 and "
                + "declares no conversion from arflex.TrajectoryState 1.0"), other.text());
        ChangeSetResult none = rig.apply(update(""));
        assertFalse(none.applied());
        assertTrue(none.refusal().contains("state block: the running version 1.0.0 hands over arflex.TrajectoryState "
                + "1.0, the new version 1.1.0 declares no state and would start from nothing"), none.text());
        assertEquals(before, fake.events.size(), "nothing launched, created or bound: " + fake.events);
        assertEquals("1.0.0", cell.instance("stage").orElseThrow().contract().version());
    }

    @Test
    void aVersionWithoutStateGetsNoAdoptAndAStatelessOneMayGainAState() throws Exception {
        runningCell("");
        assertFalse(fake.openOutputs.keySet().stream().anyMatch(n -> n.endsWith(".state")), fake.openOutputs::toString);
        ChangeSetResult r = rig.apply(update(TRAJ));
        assertTrue(r.applied(), r.text());
        assertTrue(fake.events.stream().noneMatch(e -> e.contains(" ADOPT ")), "nothing to adopt: " + fake.events);
        assertTrue(fake.openOutputs.containsKey("/arflex.t.1-stage.state"));
        fake.running.get("1-stage").stats = new ControlBlock.Stats(100, 0, 0, 0, 0, 0, 0, 0, 0, 0);
        rig.look();
        rig.stepUntil("the verdict", () -> r.verdict().isDone());
    }

    /**
     * D52: a running version that awaits an operator reset (a latched stop: RESET_REQUIRED on its
     * control block) and declares no state would hand the new half nothing, so the new half
     * would start without the stop: refused by the plan, nothing launched. With a state block
     * the latch goes over with it (the adopt hook's part) and the update is admitted.
     */
    @Test
    void aLatchedRunningHalfWithoutStateIsNotUpdatedWithStateItIs() throws Exception {
        runningCell("");
        fake.running.get("stage").flags = ControlBlock.FLAG_RESET_REQUIRED;
        int before = fake.events.size();
        ChangeSetResult r = rig.apply(update(TRAJ));
        assertFalse(r.applied(), r.text());
        assertTrue(r.refusal().contains("update stage file:/x/stage-1.1.jar: 'stage' awaits an operator reset and its "
                + "running version 1.0.0 hands over no state block: a new half would start without the stop; reset it "
                + "first, or update it outside a change set"), r.text());
        assertEquals(before, fake.events.size(), "nothing launched, created or bound: " + fake.events);
        fake.running.get("stage").flags = 0;
        ChangeSetResult ok = rig.apply(update(TRAJ));
        assertTrue(ok.applied(), "once reset it may be updated: " + ok.text());
        fake.running.get("1-stage").stats = new ControlBlock.Stats(100, 0, 0, 0, 0, 0, 0, 0, 0, 0);
        rig.look();
        rig.stepUntil("the verdict", () -> ok.verdict().isDone());
    }

    @Test
    void aLatchedRunningHalfWithStateIsUpdatedAndToldItsState() throws Exception {
        runningCell(TRAJ);
        fake.running.get("stage").flags = ControlBlock.FLAG_RESET_REQUIRED;
        ChangeSetResult r = rig.apply(update(TRAJ));
        assertTrue(r.applied(), r.text());
        rig.index("1-stage ADOPT /arflex.t.stage.state");
        fake.running.get("1-stage").stats = new ControlBlock.Stats(100, 0, 0, 0, 0, 0, 0, 0, 0, 0);
        rig.look();
        rig.stepUntil("the verdict", () -> r.verdict().isDone());
    }

    private static final String IN_GUARD = "<in name=\"safety\" type=\"arflex.SafetyState\" typeVersion=\"1.0\" "
            + "method=\"state\" safety=\"true\"><bind filter=\"(role=guard)\"/></in>";
    private static final String OUT_SAFETY = "<out name=\"safety\" type=\"arflex.SafetyState\" typeVersion=\"1.0\" "
            + "method=\"state\"/>";

    /** The stage as a component that moves hardware, its motion going to {@code through} (null: not said). */
    private static Contract moving(String version, String through, String state) throws Exception {
        String xml = CellChangeSetTest.contract("stage", "stage", IN_SRC + IN_GUARD + OUT, "50us")
                .replace("version=\"1.0.0\"", "version=\"" + version + "\"")
                .replace("movesHardware=\"false\"", "movesHardware=\"true\""
                        + (through == null ? "" : " motionThrough=\"" + through + "\""))
                .replace("</component>", state + "</component>");
        return ContractParser.create(PortTypes.builtin()).parse(xml, "test.xml");
    }

    /** src, guard, the moving stage 1.0.0 ({@code through}, {@code state}) and user, running. */
    private void movingCell(String through, String state) throws Exception {
        rig.install(parse("src", "src", OUT, "1.0.0", ""));
        rig.install(parse("guard", "guard", OUT_SAFETY, "1.0.0", ""));
        rig.install(moving("1.0.0", through, state));
        rig.install(parse("user", null, IN_STAGE, "1.0.0", ""));
    }

    /**
     * A component that moves hardware runs two halves side by side in an update's window only
     * when both versions send their motion through their outputs and both continue it from a
     * state block; a version that drives its device itself, or says nothing (fail closed), or
     * has no state is refused by the plan naming the version, and nothing is launched.
     */
    @Test
    void aMovingComponentThatDoesNotSayWhereItsMotionGoesDrivesItsDeviceAndIsNotUpdatedBesideIt() throws Exception {
        movingCell(null, TRAJ);
        int before = fake.events.size();
        ChangeSetResult device = rig.apply(ChangeSet.builder().update("stage", moving("1.1.0", "outputs", TRAJ),
                Path.of("/nonexistent/stage-1.1"), "file:/x/stage-1.1.jar", 100).build());
        assertFalse(device.applied(), device.text());
        assertTrue(device.refusal().contains("'stage' moves hardware: version 1.0.0 drives its device itself "
                + "(implementation/@motionThrough is not \"outputs\"): a new half would drive it beside the old one; "
                + "update it outside a change set"), device.text());
        assertEquals(before, fake.events.size(), "nothing launched, created or bound: " + fake.events);
    }

    @Test
    void aMovingComponentsNewVersionThatDrivesADeviceOrHasNoStateIsRefusedThroughOutputsWithStateIsCommitted()
            throws Exception {
        movingCell("outputs", TRAJ);
        int before = fake.events.size();
        ChangeSetResult device = rig.apply(ChangeSet.builder().update("stage", moving("1.1.0", "device", TRAJ),
                Path.of("/nonexistent/stage-1.1"), "file:/x/stage-1.1.jar", 100).build());
        assertFalse(device.applied(), device.text());
        assertTrue(device.refusal().contains("version 1.1.0 drives its device itself"), device.text());
        ChangeSetResult unsaid = rig.apply(ChangeSet.builder().update("stage", moving("1.1.0", null, TRAJ),
                Path.of("/nonexistent/stage-1.1"), "file:/x/stage-1.1.jar", 100).build());
        assertFalse(unsaid.applied(), unsaid.text());
        assertTrue(unsaid.refusal().contains("version 1.1.0 drives its device itself"), unsaid.text());
        assertEquals(before, fake.events.size(), "nothing launched, created or bound: " + fake.events);
        ChangeSetResult through = rig.apply(ChangeSet.builder().update("stage", moving("1.1.0", "outputs", TRAJ),
                Path.of("/nonexistent/stage-1.1"), "file:/x/stage-1.1.jar", 100).build());
        assertTrue(through.applied(), through.text());
        rig.index("1-stage ADOPT /arflex.t.stage.state");
        fake.running.get("1-stage").stats = new ControlBlock.Stats(100, 0, 0, 0, 0, 0, 0, 0, 0, 0);
        rig.look();
        rig.stepUntil("the verdict", () -> through.verdict().isDone());
        assertTrue(through.verdict().join().startsWith("update stage: committed"), through.verdict().join());
    }

    @Test
    void aMovingComponentWithoutStateIsNotUpdatedBesideItsOldHalf() throws Exception {
        movingCell("outputs", "");
        ChangeSetResult r = rig.apply(ChangeSet.builder().update("stage", moving("1.1.0", "outputs", ""),
                Path.of("/nonexistent/stage-1.1"), "file:/x/stage-1.1.jar", 100).build());
        assertFalse(r.applied(), r.text());
        assertTrue(r.refusal().contains("'stage' moves hardware: version 1.0.0 declares no state block (§12.1): a new "
                + "half would drive it beside the old one without continuing its motion"), r.text());
    }

    @Test
    void aRefusedAdoptTearsTheSetDownAndLeavesTheOldHalf() throws Exception {
        runningCell(TRAJ);
        FakeLauncher.FakeHalf old = fake.running.get("stage");
        fake.refuseAdopt.put("1-stage", "ADOPT refused by 1-stage: status -95");
        ChangeSetResult r = rig.apply(update(TRAJ));
        assertFalse(r.applied());
        assertTrue(r.refusal().startsWith("preparation failed, nothing changed: preparing 'stage': its state block: "
                + "ADOPT refused by 1-stage: status -95"), r.text());
        rig.stepUntil("the refused half stopped and its segments gone", () -> !fake.running.containsKey("1-stage")
                && fake.openOutputs.keySet().stream().noneMatch(n -> n.contains(".1-stage.")));
        assertTrue(fake.events.stream().noneMatch(e -> e.equals("1-stage START")), fake.events::toString);
        assertEquals(old, fake.running.get("stage"));
        assertTrue(fake.events.stream().noneMatch(e -> e.startsWith("user BIND x /arflex.t.1-stage")), fake.events::toString);
    }

    @Test
    void aRollbackHandsNothingBackTheOldHalfKeptPublishing() throws Exception {
        runningCell(TRAJ);
        FakeLauncher.FakeHalf old = fake.running.get("stage");
        ChangeSetResult r = rig.apply(update(TRAJ));
        assertTrue(r.applied(), r.text());
        int mark = fake.events.size();
        fake.running.get("1-stage").crash(139, "killed by signal 11");
        rig.stepUntil("the verdict", () -> r.verdict().isDone());
        assertTrue(r.verdict().join().contains("rolled back"), r.verdict().join());
        assertEquals(old.pid, cell.instance("stage").orElseThrow().half.pid());
        assertTrue(fake.openOutputs.containsKey("/arflex.t.stage.state"), "the old half's state segment stays");
        rig.stepUntil("the new state segment gone", () -> !fake.openOutputs.containsKey("/arflex.t.1-stage.state"));
        assertTrue(fake.events.subList(mark, fake.events.size()).stream().noneMatch(e -> e.contains(" ADOPT ")),
                "nothing is handed back: " + fake.events);
    }
}
