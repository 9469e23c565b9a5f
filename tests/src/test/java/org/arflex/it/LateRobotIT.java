package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.List;
import org.junit.jupiter.api.Test;

/**
 * The robot installed last (issue 7, "install the cell's bundles in any order"): the trajectory
 * and tcp-correction run first, with no robot, so the trajectory plays from its program's
 * start line and is paused half-way through its first motion, far from where the arm is. Then
 * sim-robot (and the force guard, which needs it) are installed. The arm must not be pulled
 * across to the trajectory's reference: sim-robot follows a reference only once one lies near
 * the measured arm (its {@code ref_acquire_tol}), and the trajectory, given a robot somewhere
 * else than its output, starts its program over from the measured pose. So the arm holds
 * (the trajectory is paused) within a few milliradians of its home pose, the force guard stays
 * in NORMAL, and once resumed the arm follows the program. Before this, the arm was driven at
 * the servo's full speed to the paused reference, and the force guard tripped.
 */
class LateRobotIT {

    static final long T = CellRig.T;
    static final double[] HOME = {0.0, 0.5, 0.3, 0.0, 0.8, 0.0};

    @Test
    void aRobotInstalledLastIsNotPulledToTheRunningTrajectory() throws Exception {
        CellRig.assertBuilt(CellRig.SIM_ROBOT, CellRig.TRAJECTORY, CellRig.FORCE_GUARD, CellRig.TCP_CORRECTION);
        try (Runtime rt = new Runtime("laterobot")) {
            rt.installAndStart(CellRig.TRAJECTORY);
            rt.installAndStart(CellRig.TCP_CORRECTION);
            rt.awaitState("ACTIVE", T, "trajectory", "tcp-correction");
            // The built-in program from its start line (all zeros): paused half-way through
            // its first motion.
            double[] paused;
            try (CellRig.Port ref = new CellRig.Port(rt.segment("trajectory", "joint_ref"), CellRig.REF_SIZE)) {
                rt.waitUntil("the trajectory moving away from its start line", T, () -> {
                    CellRig.Ref r = CellRig.Ref.of(ref.read());
                    return r != null && CellRig.maxDiff(r.q(), new double[6]) > 0.05;
                });
                CellRig.set(rt, "trajectory", "run", "false");
                double[][] last = {null};
                long[] still = {0};
                rt.waitUntil("the trajectory paused", T, () -> {
                    CellRig.Ref r = CellRig.Ref.of(ref.read());
                    if (r == null) {
                        return false;
                    }
                    still[0] = last[0] != null && java.util.Arrays.equals(last[0], r.q()) ? still[0] + 1 : 0;
                    last[0] = r.q();
                    return still[0] >= 50;
                });
                paused = last[0];
            }
            double away = CellRig.maxDiff(paused, HOME);
            assertTrue(away > 0.1, "the paused reference should be far from the arm's home pose for this test to"
                    + " mean anything: " + away + " rad");

            CellRig.Trace<CellRig.JointState> jsT = new CellRig.Trace<>();
            CellRig.Trace<CellRig.Safety> safetyT = new CellRig.Trace<>();
            CellRig.Trace<CellRig.Ref> refT = new CellRig.Trace<>();
            CellRig.Trace<CellRig.Ref> armRefT = new CellRig.Trace<>();
            List<CellRig.Port> ports = new java.util.ArrayList<>();
            try (CellRig.Recorder rec = new CellRig.Recorder()) {
                // Recorded from before the robot exists: what the trajectory and tcp-correction
                // write, then the robot and the guard from their first values on.
                record(rt, rec, ports, "trajectory", "joint_ref", CellRig.REF_SIZE, CellRig.Ref::of, CellRig.Ref::seq, refT::add);
                record(rt, rec, ports, "tcp-correction", "corrected", CellRig.REF_SIZE, CellRig.Ref::of, CellRig.Ref::seq,
                        armRefT::add);
                rec.start();
                rt.installAndStart(CellRig.FORCE_GUARD);
                rt.installAndStart(CellRig.SIM_ROBOT);
                rt.waitUntil("the robot's and the guard's ports created", T, () -> java.nio.file.Files.exists(
                        rt.segment("sim-robot", "joint_state")) && java.nio.file.Files.exists(rt.segment("force-guard", "safety")));
                record(rt, rec, ports, "sim-robot", "joint_state", CellRig.JOINT_STATE_SIZE, CellRig.JointState::of,
                        CellRig.JointState::seq, jsT::add);
                record(rt, rec, ports, "force-guard", "safety", CellRig.SAFETY_SIZE, CellRig.Safety::of, CellRig.Safety::seq,
                        safetyT::add);
                rt.awaitState("ACTIVE", T, "sim-robot", "force-guard", "trajectory", "tcp-correction");
                rt.waitUntil("the arm wired to the trajectory", T, () -> CellRig.armFollows(rt, "trajectory")
                        && rt.cmd("arflex:bindings").contains("trajectory.joint_state <- sim-robot.joint_state"));
                try {
                    // 2 s of the arm's own periods with the trajectory paused: the arm holds.
                    rt.waitUntil("2000 robot periods observed", T,
                            () -> jsT.size() > 0 && jsT.last().seq() - jsT.get(0).seq() >= 2000);
                    double held = jsT.snapshot().stream().mapToDouble(v -> CellRig.maxDiff(v.q(), HOME)).max().orElseThrow();
                    assertTrue(held < 0.005, "the arm was pulled " + held + " rad from its home pose towards the paused"
                            + " reference (" + away + " rad away)");
                    // Resumed: the arm follows the program from where it is, the guard stays NORMAL.
                    CellRig.set(rt, "trajectory", "run", "true");
                    rt.waitUntil("the arm moving with the program", T,
                            () -> CellRig.maxDiff(jsT.last().q(), HOME) > 0.05);
                    assertEquals(null, rec.error);
                    List<CellRig.Safety> safety = safetyT.snapshot();
                    assertTrue(safety.size() > 500, "force-guard values seen: " + safety.size());
                    for (CellRig.Safety v : safety) {
                        assertEquals(CellRig.Safety.NORMAL, v.mode(), "the force guard left NORMAL: " + v);
                    }
                    assertEquals(List.of(), CellRig.awaitingReset(rt), "components waiting for an operator reset");
                } catch (AssertionError | RuntimeException e) {
                    dump(refT.snapshot(), armRefT.snapshot(), jsT.snapshot(), safetyT.snapshot());
                    throw e;
                }
            } finally {
                for (CellRig.Port p : ports) {
                    p.close();
                }
            }
        }
    }

    /** Opens {@code instance}'s output {@code port} (kept in {@code ports} to close) and records it. */
    static <V> void record(Runtime rt, CellRig.Recorder rec, List<CellRig.Port> ports, String instance, String port, int size,
            java.util.function.Function<java.nio.ByteBuffer, V> decode, java.util.function.ToLongFunction<V> seqOf,
            java.util.function.Consumer<V> sink) throws java.io.IOException {
        CellRig.Port p = new CellRig.Port(rt.segment(instance, port), size);
        ports.add(p);
        rec.add(p, decode, seqOf, sink);
    }

    /**
     * What happened when the robot came, for a person to read: every change of the trajectory's
     * and tcp-correction's outputs, the robot's first 300 states and the guard's first 50 values,
     * in ms from the robot's first recorded state.
     */
    static void dump(List<CellRig.Ref> ref, List<CellRig.Ref> armRef, List<CellRig.JointState> js, List<CellRig.Safety> safety) {
        long t0 = js.isEmpty() ? 0 : js.get(0).tNs();
        StringBuilder b = new StringBuilder("LateRobotIT: t (ms from the robot's first recorded state)\n");
        for (var e : java.util.Map.of("ref", ref, "armref", armRef).entrySet()) {
            double[] last = null;
            for (CellRig.Ref r : e.getValue()) {
                if (last == null || CellRig.maxDiff(last, r.q()) > 1e-6) {
                    b.append(String.format("%-6s %9.3f %s%n", e.getKey(), (r.tNs() - t0) / 1e6, java.util.Arrays.toString(r.q())));
                }
                last = r.q();
            }
        }
        for (CellRig.JointState s : js.subList(0, Math.min(js.size(), 300))) {
            b.append(String.format("js     %9.3f %s%n", (s.tNs() - t0) / 1e6, java.util.Arrays.toString(s.q())));
        }
        for (CellRig.Safety s : safety.subList(0, Math.min(safety.size(), 50))) {
            b.append(String.format("safety %9.3f %s%n", (s.tNs() - t0) / 1e6, s));
        }
        System.out.println(b);
    }

    static <V> int indexAfter(List<V> l, long t, java.util.function.ToLongFunction<V> tOf) {
        for (int i = 0; i < l.size(); i++) {
            if (tOf.applyAsLong(l.get(i)) >= t) {
                return i;
            }
        }
        return l.size();
    }
}
