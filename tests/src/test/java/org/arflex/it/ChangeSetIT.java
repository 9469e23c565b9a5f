package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.file.Path;
import java.util.List;
import java.util.Locale;
import org.junit.jupiter.api.Test;

/**
 * docs/DECISIONS.md D35 through the real runtime: on the moving arm (FailSafeIT's looping
 * program), teach replaces trajectory as one change set, {@code arflex:change apply install teach
 * uninstall trajectory}. teach's RT half is spawned and READY while trajectory drives the arm;
 * in one actor turn teach is started (its reference starts at the arm's measured joints) and
 * tcp-correction is bound to it; then trajectory stops.
 *
 * <p>Asserted: the set is applied; the force guard never leaves NORMAL, sim-robot never enters
 * safe mode and nothing waits for a reset or a fresh command; teach, tcp-correction, sim-robot
 * and the guard stay ACTIVE with the same pids, trajectory is gone with its process and ports,
 * its bundle stopped, teach's bundle started. Measured and printed: the largest step of the
 * robot's reference (tcp-correction.corrected, what sim-robot servoes to) between two values the
 * test saw around the switch, against the largest step before the switch (the program's own
 * motion). Bound: {@link #JUMP_BOUND}.
 */
class ChangeSetIT {

    static final long T = CellRig.T;
    /**
     * Bound on the robot's reference step per cycle of its source from the apply on, rad (any
     * joint): one cycle of the program's fastest motion (speed 0.1 of joint 0's 123 deg/s: 0.215
     * mrad per 1 ms; teach's take-over ramp starts at the arm's speed and only slows down), plus
     * the steepest step of tcp-correction's fade of a provider change (D35: a quintic over 0.5 s
     * of at most 50 mrad: 1.875 x 50 mrad / 0.5 s = 0.19 mrad per cycle), plus its correction's
     * rate limit (0.01 rad/s: 0.01 mrad per cycle): 0.41 mrad. "Per cycle of its source": the
     * step between two values the test saw, divided by the source cycles between their stamps
     * (tcp-correction passes its source's t_ns on), because the stage and the motion source are
     * two processes: a stage cycle that finds no new reference is followed by one that finds two
     * (0.36-0.60 mrad per stage cycle measured before the switch, for 0.21 mrad of motion).
     * Without the fade the step is the arm's whole lag behind the trajectory's reference (about
     * 6.5 mrad at this speed), which the force guard read as some 770 N and stopped the arm.
     */
    static final double JUMP_BOUND = (0.1 * CellRig.VMAX[0] + 1.875 * 0.05 / 0.5 + 0.01) * 1e-3;

    /**
     * The step between two values of the robot's reference the test saw, per cycle of their
     * source: divided by the source periods (1 ms) between their stamps, at least one.
     */
    static double perSourceCycle(CellRig.Ref a, CellRig.Ref b) {
        long cycles = Math.max(1, Math.round((b.tNs() - a.tNs()) / 1e6));
        return CellRig.maxDiff(b.q(), a.q()) / cycles;
    }

    @SuppressWarnings("unchecked")
    static java.util.Map<String, Object> stats(Runtime rt, String name) {
        return (java.util.Map<String, Object>) rt.instance(name).get("stats");
    }

    static long delta(java.util.Map<String, Object> a, java.util.Map<String, Object> b, String field) {
        return ((Number) b.get(field)).longValue() - ((Number) a.get(field)).longValue();
    }

    @Test
    void teachReplacesTrajectoryOnTheMovingArmWithoutSafeStopOrReset() throws Exception {
        CellRig.assertBuilt(CellRig.SIM_ROBOT, CellRig.TRAJECTORY, CellRig.FORCE_GUARD, CellRig.TEACH);
        try (Runtime rt = new Runtime("changeset-teach")) {
            List<String> cell = FailSafeIT.movingCell(rt);
            assertTrue(cell.contains("tcp-correction"), "the arm's reference comes through tcp-correction: " + cell);
            long teachBundle = CellRig.installOnly(rt, CellRig.TEACH, "teach");
            assertEquals("INSTALLED", rt.state("teach"));

            String dry = rt.cmd("arflex:change plan install teach uninstall trajectory");
            System.out.println("ChangeSetIT: dry run:\n" + dry);
            assertTrue(dry.contains("admitted (dry run: nothing changed)"), dry);
            assertTrue(dry.contains("START    teach") && dry.contains("STOP     trajectory")
                    && dry.contains("REBIND   tcp-correction"), dry);
            assertEquals("INSTALLED", rt.state("teach"), "a dry run changes nothing");
            // teach beside trajectory would make tcp-correction's reference ambiguous and stop it:
            // the set is refused whole, naming the component, and nothing is spawned
            String refused = rt.cmd("arflex:change apply install teach");
            System.out.println("ChangeSetIT: refused:\n" + refused);
            assertTrue(refused.startsWith("error: change set: install teach\nrefused: the set would stop 'tcp-correction'"),
                    refused);
            assertEquals("INSTALLED", rt.state("teach"));
            assertTrue(Runtime.rtProcesses(rt.rid).stream().noneMatch(p -> p.contains("--instance teach ")));
            assertFalse(java.nio.file.Files.exists(rt.segment("teach", "joint_ref")), "no segment of a refused set");

            long robotPid = rt.pid("sim-robot");
            long guardPid = rt.pid("force-guard");
            long corrPid = rt.pid("tcp-correction");
            CellRig.Trace<CellRig.Ref> ref = new CellRig.Trace<>();
            CellRig.Trace<CellRig.JointState> js = new CellRig.Trace<>();
            CellRig.Trace<CellRig.Safety> safety = new CellRig.Trace<>();
            CellRig.Trace<CellRig.Ref> tr = new CellRig.Trace<>();
            try (CellRig.Port rp = new CellRig.Port(rt.segment("tcp-correction", "corrected"), CellRig.REF_SIZE);
                    CellRig.Port jp = new CellRig.Port(rt.segment("sim-robot", "joint_state"), CellRig.JOINT_STATE_SIZE);
                    CellRig.Port sp = new CellRig.Port(rt.segment("force-guard", "safety"), CellRig.SAFETY_SIZE);
                    CellRig.Port tp = new CellRig.Port(rt.segment("trajectory", "joint_ref"), CellRig.REF_SIZE);
                    CellRig.Recorder rec = new CellRig.Recorder()) {
                rec.add(rp, CellRig.Ref::of, CellRig.Ref::seq, ref::add);
                rec.add(jp, CellRig.JointState::of, CellRig.JointState::seq, js::add);
                rec.add(sp, CellRig.Safety::of, CellRig.Safety::seq, safety::add);
                rec.add(tp, CellRig.Ref::of, CellRig.Ref::seq, tr::add);
                rec.start();
                rt.waitUntil("the arm moving and 1000 references seen", T,
                        () -> FailSafeIT.moving(js) && ref.size() > 1000);
                assertTrue(CellRig.awaitingReset(rt).isEmpty(), "before: " + CellRig.awaitingReset(rt));

                java.util.Map<String, Object> robot0 = stats(rt, "sim-robot");
                int mark = ref.size();
                int logMark = rt.logMark();
                int jsMark = js.size();
                long t0 = System.nanoTime();
                String out = rt.cmd("arflex:change apply install teach uninstall trajectory");
                long tookMs = (System.nanoTime() - t0) / 1_000_000;
                System.out.println("ChangeSetIT: apply (" + tookMs + " ms):\n" + out);
                assertTrue(out.contains("\napplied: "), out);
                int after = ref.size();
                rt.waitUntil("2000 references after the switch", T, () -> ref.size() > after + 2000);
                assertNull(rec.error, () -> "recorder: " + rec.error);

                // the switch: where the references stop following trajectory
                List<CellRig.Ref> rs = ref.snapshot();
                double before = 0;
                double beforeRaw = 0;
                for (int i = 1; i < mark; i++) {
                    before = Math.max(before, perSourceCycle(rs.get(i - 1), rs.get(i)));
                    beforeRaw = Math.max(beforeRaw, CellRig.maxDiff(rs.get(i).q(), rs.get(i - 1).q())
                            / Math.max(1, rs.get(i).seq() - rs.get(i - 1).seq()));
                }
                double jump = 0;
                double jumpRaw = 0;
                for (int i = Math.max(1, mark); i < rs.size(); i++) {
                    jump = Math.max(jump, perSourceCycle(rs.get(i - 1), rs.get(i)));
                    jumpRaw = Math.max(jumpRaw, CellRig.maxDiff(rs.get(i).q(), rs.get(i - 1).q())
                            / Math.max(1, rs.get(i).seq() - rs.get(i - 1).seq()));
                }
                // The switch: the last value of the robot's reference stamped by trajectory (the
                // stage passes its source's t_ns on); teach starts at the arm measured then, so
                // its first reference lies the arm's lag away from trajectory's last.
                java.util.Set<Long> trajStamps = new java.util.HashSet<>();
                for (CellRig.Ref r : tr.snapshot()) {
                    trajStamps.add(r.tNs());
                }
                int sw = -1;
                for (int i = mark; i < rs.size(); i++) {
                    if (trajStamps.contains(rs.get(i).tNs())) {
                        sw = i;
                    }
                }
                assertTrue(sw >= mark && sw < rs.size() - 1, "the switch not found in the references recorded");
                CellRig.Ref lastTraj = rs.get(sw);
                CellRig.JointState atSwitch = js.snapshot().stream().min(java.util.Comparator.comparingLong(
                        x -> Math.abs(x.tNs() - lastTraj.tNs()))).orElseThrow();
                double lag = CellRig.maxDiff(lastTraj.q(), atSwitch.q());
                System.out.printf(Locale.ROOT, "ChangeSetIT: at the switch the arm lagged trajectory's reference by "
                        + "%.3f mrad (moving at %.3f rad/s): teach's reference starts there, faded over 0.5 s by "
                        + "tcp-correction%n", lag * 1e3, atSwitch.maxSpeed());
                long lost = 0;
                List<CellRig.JointState> j = js.snapshot();
                for (int i = 1; i < j.size(); i++) {
                    lost = Math.max(lost, j.get(i).seq() - j.get(i - 1).seq() - 1);
                }
                System.out.printf(Locale.ROOT, "ChangeSetIT: largest step of the robot's reference from the apply on: "
                        + "%.3f mrad per source cycle (bound %.3f), %.3f per stage cycle; before the apply (the "
                        + "program's motion): %.3f per source cycle, %.3f per stage cycle; change set applied in %d ms;"
                        + " largest run of sim-robot states the test missed: %d%n", jump * 1e3, JUMP_BOUND * 1e3,
                        jumpRaw * 1e3, before * 1e3, beforeRaw * 1e3, tookMs, lost);
                assertTrue(jump <= JUMP_BOUND, "reference step " + jump + " rad per source cycle from the apply on");
                SwitchWindow.of(rt.logSince(logMark)).assertNoReleaseLost("ChangeSetIT", js.snapshot());

                // no safe stop, no reset
                List<CellRig.Safety> ss = safety.snapshot();
                CellRig.Safety worst = ss.stream().max(java.util.Comparator.comparingDouble(CellRig.Safety::forceNorm))
                        .orElseThrow();
                System.out.printf(Locale.ROOT, "ChangeSetIT: largest force the guard read: %.1f N (limit %.0f N)%n",
                        worst.forceNorm(), worst.forceLimit());
                CellRig.Safety tripped = ss.stream().filter(s -> s.mode() != CellRig.Safety.NORMAL).findFirst().orElse(null);
                if (tripped != null) {
                    System.out.println("ChangeSetIT: the runtime since the apply:\n" + String.join("\n", rt.logSince(logMark)));
                    for (CellRig.JointState x : js.since(jsMark)) {
                        if (x.tNs() > tripped.tNs() - 400_000_000L && x.tNs() <= tripped.tNs()) {
                            System.out.printf(Locale.ROOT, "js t=%.1f ms q0=%.5f qd0=%.4f qd1=%.4f qd2=%.4f%n",
                                    (x.tNs() - tripped.tNs()) / 1e6, x.q()[0], x.qd()[0], x.qd()[1], x.qd()[2]);
                        }
                    }
                    for (CellRig.Ref x : ref.since(mark)) {
                        if (x.tNs() > tripped.tNs() - 400_000_000L && x.tNs() <= tripped.tNs()) {
                            System.out.printf(Locale.ROOT, "ref t=%.1f ms q=%s%n", (x.tNs() - tripped.tNs()) / 1e6,
                                    java.util.Arrays.toString(x.q()));
                        }
                    }
                }
                assertNull(tripped, "the guard left NORMAL: " + tripped);
                int robotFlags = CellPorts.ctlFlags(Path.of("/dev/shm/arflex." + rt.rid + ".sim-robot.ctl"));
                assertEquals(0, robotFlags & CellPorts.FLAG_SAFE_ACTIVE, "sim-robot in safe mode");
                assertEquals(List.of(), CellRig.awaitingReset(rt));
                assertEquals(List.of(), CellRig.awaitingCommand(rt));
                assertNull(FailSafeIT.holding(rt, "sim-robot"));
                java.util.Map<String, Object> robot1 = stats(rt, "sim-robot");
                System.out.printf(Locale.ROOT, "ChangeSetIT: sim-robot from the apply to 2000 references after: "
                        + "%d cycles, %d overruns, %d safe cycles, %d update errors%n",
                        delta(robot0, robot1, "cycles"), delta(robot0, robot1, "overruns"),
                        delta(robot0, robot1, "safeCycles"), delta(robot0, robot1, "updateErrors"));
                assertEquals(0, delta(robot0, robot1, "safeCycles"), "sim-robot ran safe cycles");
            }
            rt.awaitState("ACTIVE", T, "teach", "tcp-correction", "sim-robot", "force-guard");
            assertEquals(robotPid, rt.pid("sim-robot"));
            assertEquals(guardPid, rt.pid("force-guard"));
            assertEquals(corrPid, rt.pid("tcp-correction"));
            assertTrue(CellRig.armFollows(rt, "teach"), rt.cmd("arflex:bindings"));
            rt.waitUntil("trajectory's process and port gone", T, () -> Runtime.rtProcesses(rt.rid).stream()
                    .noneMatch(p -> p.contains("--instance trajectory ")) && !java.nio.file.Files.exists(
                    rt.segment("trajectory", "joint_ref")));
            String list = rt.cmd("arflex:list");
            assertTrue(list.lines().anyMatch(l -> l.startsWith("trajectory ") && l.contains("INSTALLED")), list);
            String lb = rt.cmd("lb");
            assertTrue(lb.lines().anyMatch(l -> l.trim().startsWith(teachBundle + "|Active")), lb);
            assertFalse(rt.cmd("arflex:list").contains("FAILED"), rt.cmd("arflex:list"));
        }
    }
}
