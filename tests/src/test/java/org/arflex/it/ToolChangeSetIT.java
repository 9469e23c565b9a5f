package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.file.Files;
import java.nio.file.Path;
import java.util.List;
import java.util.Locale;
import java.util.Map;
import org.junit.jupiter.api.Test;

/**
 * Issue #19's "the spindle replaces the gripper" as one change set on the moving arm
 * (docs/DECISIONS.md D40): FailSafeIT's looping program with the gripper mounted (trajectory's
 * optional {@code tool} input bound to it, its safety input to the guard), the spindle's bundle
 * installed but not started, then {@code arflex:change apply install tool-spindle uninstall
 * tool-gripper}: the spindle is spawned and READY while the gripper is mounted, and in one actor
 * turn it is started and trajectory gets one BIND of its tool input to it; then the gripper stops.
 * ToolSwapIT does the same as two separate changes (the flange between them).
 *
 * <p>Asserted: the set is applied; trajectory plans for the spindle (tool_id 2) and its tool
 * input follows it; the guard never leaves NORMAL and sim-robot runs no safe cycle; nothing waits
 * for a reset or a fresh command; sim-robot, the guard, trajectory and tcp-correction keep their
 * pids; the gripper's process and port are gone; the robot's reference never steps more than
 * ChangeSetIT's bound per cycle of its source from the apply on; the spindle, commanded after
 * the set, spins up (a tool installed by a set is a start, not a restart: no reset to take).
 */
class ToolChangeSetIT {

    static final long T = CellRig.T;

    @Test
    void theSpindleReplacesTheGripperOnTheMovingArm() throws Exception {
        CellRig.assertBuilt(CellRig.SIM_ROBOT, CellRig.TRAJECTORY, CellRig.FORCE_GUARD, CellRig.GRIPPER, CellRig.SPINDLE);
        try (Runtime rt = new Runtime("changeset-tool")) {
            FailSafeIT.movingCell(rt);
            long gripper = rt.installAndStart(CellRig.GRIPPER);
            rt.awaitState("ACTIVE", T, "tool-gripper");
            rt.waitUntil("trajectory.tool bound to the gripper", T,
                    () -> rt.cmd("arflex:bindings").contains("trajectory.tool <- tool-gripper.tool"));
            rt.waitUntil("tool-gripper.safety bound to the guard", T,
                    () -> rt.cmd("arflex:bindings").contains("tool-gripper.safety <- force-guard.safety"));
            long spindle = CellRig.installOnly(rt, CellRig.SPINDLE, "tool-spindle");
            assertEquals("INSTALLED", rt.state("tool-spindle"));

            String dry = rt.cmd("arflex:change plan install tool-spindle uninstall tool-gripper");
            System.out.println("ToolChangeSetIT: dry run:\n" + dry);
            assertTrue(dry.contains("admitted (dry run: nothing changed)"), dry);
            assertTrue(dry.contains("START    tool-spindle") && dry.contains("STOP     tool-gripper")
                    && dry.contains("REBIND   trajectory"), dry);

            assertTrue(Runtime.rtProcesses(rt.rid).stream().anyMatch(p -> p.contains("--instance tool-gripper ")),
                    "the gripper's process is seen before the set");
            long robotPid = rt.pid("sim-robot");
            long guardPid = rt.pid("force-guard");
            long trajPid = rt.pid("trajectory");
            long corrPid = rt.pid("tcp-correction");
            CellRig.Trace<CellRig.Ref> ref = new CellRig.Trace<>();
            CellRig.Trace<CellRig.JointState> js = new CellRig.Trace<>();
            CellRig.Trace<CellRig.Safety> safety = new CellRig.Trace<>();
            try (CellRig.Port rp = new CellRig.Port(rt.segment("tcp-correction", "corrected"), CellRig.REF_SIZE);
                    CellRig.Port jp = new CellRig.Port(rt.segment("sim-robot", "joint_state"), CellRig.JOINT_STATE_SIZE);
                    CellRig.Port sp = new CellRig.Port(rt.segment("force-guard", "safety"), CellRig.SAFETY_SIZE);
                    CellRig.Port toolId = new CellRig.Port(rt.segment("trajectory", "tool_id"), CellRig.SAMPLE_SIZE);
                    CellRig.Recorder rec = new CellRig.Recorder()) {
                rec.add(rp, CellRig.Ref::of, CellRig.Ref::seq, ref::add);
                rec.add(jp, CellRig.JointState::of, CellRig.JointState::seq, js::add);
                rec.add(sp, CellRig.Safety::of, CellRig.Safety::seq, safety::add);
                rec.start();
                rt.waitUntil("trajectory plans for the gripper (tool_id 1)", T, () -> ToolSwapIT.toolIdIs(toolId, 1));
                rt.waitUntil("the arm moving and 1000 references seen", T,
                        () -> FailSafeIT.moving(js) && ref.size() > 1000);
                assertTrue(CellRig.awaitingReset(rt).isEmpty(), "before: " + CellRig.awaitingReset(rt));

                Map<String, Object> robot0 = ChangeSetIT.stats(rt, "sim-robot");
                int mark = ref.size();
                int logMark = rt.logMark();
                long t0 = System.nanoTime();
                String out = rt.cmd("arflex:change apply install tool-spindle uninstall tool-gripper");
                System.out.printf(Locale.ROOT, "ToolChangeSetIT: apply (%.0f ms):%n%s%n", (System.nanoTime() - t0) / 1e6, out);
                assertTrue(out.contains("\napplied: "), out);
                rt.waitUntil("trajectory plans for the spindle (tool_id 2)", T, () -> ToolSwapIT.toolIdIs(toolId, 2));
                int after = ref.size();
                rt.waitUntil("2000 references after the switch", T, () -> ref.size() > after + 2000);
                assertNull(rec.error, () -> "recorder: " + rec.error);

                List<CellRig.Ref> rs = ref.snapshot();
                double before = ReconfigBench.steps(rs.subList(0, mark));
                double jump = ReconfigBench.steps(rs.subList(Math.max(0, mark - 1), rs.size()));
                List<CellRig.Safety> ss = safety.snapshot();
                double force = ss.stream().mapToDouble(CellRig.Safety::forceNorm).max().orElseThrow();
                Map<String, Object> robot1 = ChangeSetIT.stats(rt, "sim-robot");
                System.out.printf(Locale.ROOT, "ToolChangeSetIT: largest step of the robot's reference from the apply on "
                        + "%.3f mrad per source cycle (bound %.3f; before %.3f); largest force %.1f N; sim-robot %d cycles, "
                        + "%d overruns, %d safe cycles%n", jump * 1e3, ChangeSetIT.JUMP_BOUND * 1e3, before * 1e3, force,
                        ChangeSetIT.delta(robot0, robot1, "cycles"), ChangeSetIT.delta(robot0, robot1, "overruns"),
                        ChangeSetIT.delta(robot0, robot1, "safeCycles"));
                assertTrue(jump <= ChangeSetIT.JUMP_BOUND, "reference step " + jump + " rad per source cycle");
                SwitchWindow.of(rt.logSince(logMark)).assertNoReleaseLost("ToolChangeSetIT", js.snapshot());
                assertNull(ss.stream().filter(s -> s.mode() != CellRig.Safety.NORMAL).findFirst().orElse(null),
                        "the guard left NORMAL");
                assertEquals(0, ChangeSetIT.delta(robot0, robot1, "safeCycles"), "sim-robot ran safe cycles");
                int robotFlags = CellPorts.ctlFlags(Path.of("/dev/shm/arflex." + rt.rid + ".sim-robot.ctl"));
                assertEquals(0, robotFlags & CellPorts.FLAG_SAFE_ACTIVE, "sim-robot in safe mode");
            }
            assertEquals(List.of(), CellRig.awaitingReset(rt));
            assertEquals(List.of(), CellRig.awaitingCommand(rt));
            assertNull(FailSafeIT.holding(rt, "sim-robot"));
            assertNull(FailSafeIT.holding(rt, "trajectory"));
            rt.awaitState("ACTIVE", T, "tool-spindle", "trajectory", "tcp-correction", "sim-robot", "force-guard");
            assertEquals(robotPid, rt.pid("sim-robot"));
            assertEquals(guardPid, rt.pid("force-guard"));
            assertEquals(trajPid, rt.pid("trajectory"));
            assertEquals(corrPid, rt.pid("tcp-correction"));
            String b = rt.cmd("arflex:bindings");
            assertTrue(b.contains("trajectory.tool <- tool-spindle.tool") && b.contains("tool-spindle.safety <- force-guard.safety"), b);
            rt.waitUntil("the gripper's process and port gone", T, () -> Runtime.rtProcesses(rt.rid).stream()
                    .noneMatch(p -> p.contains("--instance tool-gripper ")) && !Files.exists(rt.segment("tool-gripper", "tool")));
            String list = rt.cmd("arflex:list");
            assertTrue(list.lines().anyMatch(l -> l.startsWith("tool-gripper ") && l.contains("INSTALLED")), list);
            assertFalse(list.contains("FAILED"), list);
            String lb = rt.cmd("lb");
            assertTrue(lb.lines().anyMatch(l -> l.trim().startsWith(spindle + "|Active")), lb);
            assertTrue(lb.lines().noneMatch(l -> l.trim().startsWith(gripper + "|Active")), lb);
            // installed by the set, not restarted: the spindle spins up when commanded, no reset to take
            CellRig.set(rt, "tool-spindle", "command", "0.5");
            try (CellRig.Port tool = new CellRig.Port(rt.segment("tool-spindle", "tool"), ToolSwapIT.TOOL_STATE_SIZE)) {
                rt.waitUntil("the spindle at speed 0.5", T, () -> {
                    java.nio.ByteBuffer v = tool.read();
                    return v != null && v.getDouble(ToolSwapIT.TOOL_LEVEL) == 0.5;
                });
            }
        }
    }
}
