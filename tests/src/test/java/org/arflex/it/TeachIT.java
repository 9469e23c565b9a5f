package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import org.junit.jupiter.api.Test;

/**
 * Teaching by hand guiding through the real runtime (issue 7). The cell has one motion source
 * at a time: first teach (role=motion) drives the arm. In teach mode a scripted hand on the
 * simulated arm (sim-robot guide_force_n: a spring pulling the TCP 0.15 m along +y) moves it
 * through teach's admittance; teach records the path and, on a save edge, writes
 * {@code <runtime>/data/program-1.arp}. Installing trajectory beside teach would make the
 * reference stage's input ambiguous: the dry run says so by name. Teach is uninstalled,
 * trajectory installed and switched to program 1: the measured arm (sim-robot joint_state)
 * passes every recorded waypoint within the stated tolerance and ends on the last one.
 */
class TeachIT {

    static final long T = CellRig.T;
    /** Stated tolerance: every recorded waypoint within 2 mrad (any joint) of the measured replay. */
    static final double TOL_RAD = 2e-3;

    @Test
    void guidedPathIsRecordedSavedAndReplayed() throws Exception {
        CellRig.assertBuilt(CellRig.SIM_ROBOT, CellRig.TEACH, CellRig.TRAJECTORY);
        try (Runtime rt = new Runtime("teach")) {
            List<String> cell = new ArrayList<>(CellRig.installArm(rt));
            long teach = rt.installAndStart(CellRig.TEACH);
            cell.add("teach");
            rt.awaitState("ACTIVE", T, cell.toArray(String[]::new));
            rt.waitUntil("the arm follows teach", T, () -> CellRig.armFollows(rt, "teach"));
            Path program = rt.dir.resolve("data").resolve("program-1.arp");
            assertTrue(!Files.exists(program), "a program-1.arp exists before teaching: " + program);

            CellRig.Trace<CellRig.Ref> taught = new CellRig.Trace<>();
            try (CellRig.Port tp = new CellRig.Port(rt.segment("teach", "joint_ref"), CellRig.REF_SIZE);
                    CellRig.Recorder rec = new CellRig.Recorder()) {
                rec.add(tp, CellRig.Ref::of, CellRig.Ref::seq, taught::add);
                rec.start();
                rt.waitUntil("teach writes its reference", T, () -> taught.size() > 10);
                double[] q0 = taught.last().q().clone();

                // Teach mode on; a hand pulls the tool 0.15 m along +y over 2 s (60 N at most).
                CellRig.set(rt, "teach", "teach", "true");
                CellRig.set(rt, "sim-robot", "guide_dx", "0");
                CellRig.set(rt, "sim-robot", "guide_dy", "0.15");
                CellRig.set(rt, "sim-robot", "guide_dz", "0");
                CellRig.set(rt, "sim-robot", "guide_duration_ms", "2000");
                CellRig.set(rt, "sim-robot", "guide_force_n", "60");
                rt.waitUntil("the arm yields to the hand (joint 1 moved 30 mrad)", T,
                        () -> Math.abs(taught.last().q()[0] - q0[0]) > 0.03);
                // ... and comes to rest at the hand's target (no change for 500 teach cycles).
                rt.waitUntil("the guided arm at rest", T, () -> {
                    List<CellRig.Ref> s = taught.snapshot();
                    CellRig.Ref last = s.get(s.size() - 1);
                    for (int i = s.size() - 1; i >= 0 && last.seq() - s.get(i).seq() <= 500; i--) {
                        if (CellRig.maxDiff(s.get(i).q(), last.q()) > 1e-6) {
                            return false;
                        }
                    }
                    return last.seq() - s.get(0).seq() > 500;
                });
                CellRig.set(rt, "sim-robot", "guide_force_n", "0");
                CellRig.set(rt, "teach", "teach", "false");
                CellRig.set(rt, "teach", "save", "true");
                rt.waitUntil("program-1.arp saved", T, () -> Files.exists(program));
                rec.close();
                assertNull(rec.error, String.valueOf(rec.error));
            }
            List<double[]> wps = readWaypoints(program);
            double[] first = wps.get(0);
            double[] end = wps.get(wps.size() - 1);
            System.out.printf("TeachIT: %d waypoints saved to %s; joint 1 taught from %.4f to %.4f rad%n", wps.size(),
                    program.getFileName(), first[0], end[0]);
            assertTrue(wps.size() >= 5, "too few waypoints: " + wps.size());
            assertTrue(Math.abs(end[0] - first[0]) > 0.03, "the taught path does not move joint 1");

            // One motion source at a time: with trajectory beside teach the reference stage's
            // input would match both; the dry run names them.
            String plan = rt.cmd("arflex:plan install " + CellRig.TRAJECTORY.toUri());
            System.out.println("TeachIT: plan install trajectory while teach runs:\n" + plan);
            assertTrue(plan.contains("ambiguous") && plan.contains("teach.joint_ref") && plan.contains("trajectory.joint_ref"),
                    "the dry run does not report the ambiguity by name:\n" + plan);

            CellRig.uninstall(rt, teach, "teach", "joint_ref");
            CellRig.Trace<CellRig.JointState> replay = new CellRig.Trace<>();
            try (CellRig.Port jp = new CellRig.Port(rt.segment("sim-robot", "joint_state"), CellRig.JOINT_STATE_SIZE);
                    CellRig.Recorder rec = new CellRig.Recorder()) {
                rec.add(jp, CellRig.JointState::of, CellRig.JointState::seq, replay::add);
                rec.start();
                // Replay at 4 % of the joint speed limits: the simulated arm follows it with a lag
                // that bows the measured path by ~0.8 mrad (1.6 mrad at 8 %).
                CellRig.startTrajectory(rt, 1, "speed", "0.04");
                rt.waitUntil("the arm follows the trajectory", T, () -> CellRig.armFollows(rt, "trajectory"));
                try {
                    // Done: the measured arm back on the first waypoint once (the replay's leading
                    // ptp), then on the last one, at rest (unchanged over 200 robot cycles).
                    rt.waitUntil("the replay ends on the last waypoint (measured, 0.5 mrad, at rest)", T, () -> {
                        List<CellRig.JointState> rs = replay.snapshot();
                        int back = -1;
                        for (int i = 0; i < rs.size() && back < 0; i++) {
                            if (CellRig.maxDiff(rs.get(i).q(), first) < 5e-4) {
                                back = i;
                            }
                        }
                        if (back < 0 || rs.size() < 2) {
                            return false;
                        }
                        CellRig.JointState last = rs.get(rs.size() - 1);
                        if (CellRig.maxDiff(last.q(), end) >= 5e-4) {
                            return false;
                        }
                        for (int i = rs.size() - 1; i > back && last.seq() - rs.get(i).seq() <= 200; i--) {
                            if (CellRig.maxDiff(rs.get(i).q(), last.q()) > 1e-6) {
                                return false;
                            }
                        }
                        return last.seq() - rs.get(back).seq() > 200;
                    });
                } catch (AssertionError e) {
                    try (CellRig.Port rp = new CellRig.Port(rt.segment("trajectory", "joint_ref"), CellRig.REF_SIZE)) {
                        System.out.println("TeachIT: at the failure: trajectory.joint_ref " + java.util.Arrays.toString(
                                CellRig.Ref.of(rp.read()).q()) + ", measured " + java.util.Arrays.toString(replay.last().q())
                                + ", last waypoint " + java.util.Arrays.toString(end) + ", worst waypoint distance "
                                + passedAll(replay.snapshot(), wps));
                    }
                    System.out.println("TeachIT: " + rt.cmd("arflex:stats sim-robot").replace('\n', ' '));
                    List<CellRig.JointState> rs = replay.snapshot();
                    for (double[] w : wps) {
                        System.out.println("TeachIT: waypoint " + java.util.Arrays.toString(w) + " at "
                                + passedAll(rs, List.of(w)));
                    }
                    throw e;
                }
                rec.close();
                assertNull(rec.error, String.valueOf(rec.error));
            }
            List<CellRig.JointState> rs = replay.snapshot();
            double worst = passedAll(rs, wps);
            StringBuilder per = new StringBuilder();
            for (double[] w : wps) {
                per.append(String.format(" %.3f", passedAll(rs, List.of(w)) * 1e3));
            }
            System.out.println("TeachIT: per waypoint (mrad):" + per);
            System.out.printf("TeachIT: replay (%d joint_state values): every waypoint within %.3f mrad of the measured"
                    + " arm (tolerance %.1f mrad)%n", replay.size(), worst * 1e3, TOL_RAD * 1e3);
            assertTrue(worst < TOL_RAD, "replay missed a waypoint by " + worst + " rad");
            assertEquals("ACTIVE", rt.state("trajectory"));
        }
    }

    /**
     * A bad program file in the data directory: the trajectory's RT half refuses to start and
     * the DRCR's reason carries its {@code file:line: what} (here a joint target outside the
     * limits on line 3); nothing of it is left running.
     */
    @Test
    void aBadProgramFileIsReportedWithFileAndLine() throws Exception {
        CellRig.assertBuilt(CellRig.TRAJECTORY);
        try (Runtime rt = new Runtime("teach-badprogram")) {
            Files.createDirectories(rt.dir.resolve("data"));
            Files.writeString(rt.dir.resolve("data/program-3.arp"),
                    "arflex-program 1\nptp 0 0.2 0.5 0 0.6 0\nptp 0 0.2 0.5 0 0.6 9\n");
            long id = rt.installAndStart(CellRig.TRAJECTORY);
            String[] reason = {""};
            rt.waitUntil("the trajectory's start refused naming program-3.arp:3", T, () -> {
                var i = rt.instance("trajectory");
                reason[0] = i == null ? "" : String.valueOf(i.get("failureReason"));
                return reason[0].contains("program-3.arp:3:");
            });
            System.out.println("TeachIT: bad program reported as: " + reason[0].lines().filter(l -> l.contains("program-3.arp"))
                    .findFirst().orElse(reason[0]));
            assertTrue(reason[0].contains("joint 6"), reason[0]);
            assertEquals("", rt.cmd("uninstall " + id));
        }
    }

    /** The joint vectors of a program written by teach: start, then every ptp/via target. */
    static List<double[]> readWaypoints(Path p) throws java.io.IOException {
        List<double[]> l = new ArrayList<>();
        for (String line : Files.readAllLines(p)) {
            String[] t = line.trim().split("\\s+");
            if (t.length >= 7 && (t[0].equals("start") || t[0].equals("ptp") || t[0].equals("via"))) {
                double[] q = new double[6];
                for (int j = 0; j < 6; j++) {
                    q[j] = Double.parseDouble(t[j + 1]);
                }
                l.add(q);
            }
        }
        return l;
    }

    /**
     * Largest distance (max over joints) from a waypoint to the measured path: the polyline
     * through the recorded joint_state values (the recorder may miss a value between two).
     */
    static double passedAll(List<CellRig.JointState> js, List<double[]> wps) {
        double worst = 0;
        for (double[] w : wps) {
            double best = Double.MAX_VALUE;
            for (int i = 1; i < js.size(); i++) {
                double[] a = js.get(i - 1).q();
                double[] b = js.get(i).q();
                double num = 0;
                double den = 0;
                for (int j = 0; j < 6; j++) {
                    num += (w[j] - a[j]) * (b[j] - a[j]);
                    den += (b[j] - a[j]) * (b[j] - a[j]);
                }
                double t = den > 0 ? Math.max(0, Math.min(1, num / den)) : 0;
                double d = 0;
                for (int j = 0; j < 6; j++) {
                    d = Math.max(d, Math.abs(a[j] + t * (b[j] - a[j]) - w[j]));
                }
                best = Math.min(best, d);
            }
            worst = Math.max(worst, best);
        }
        return worst;
    }
}
