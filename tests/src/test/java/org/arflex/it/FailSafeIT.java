package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.file.Files;
import java.util.List;
import org.junit.jupiter.api.Test;

/**
 * Issue 15 through the real runtime, with the arm moving (a looping program): faults from
 * outside must stop it, visibly, until an operator resets AND gives a fresh command.
 *
 * <ul>
 * <li>Finding 1: force-guard's RT half killed -9 four times (each 0.3 s after its restart) goes
 * FAILED; the arm (sim-robot's joint_state) stops within a stated time of the first kill and
 * stays stopped; sim-robot is HOLDING with its safety input named; its reset is refused while
 * the guard is gone.</li>
 * <li>Finding 3: after the guard is back and everything is reset, nothing moves until
 * {@code arflex:set trajectory run true}; the same after trajectory itself was killed and
 * restarted: {@code arflex:reset trajectory} alone does not restart the program.</li>
 * <li>Finding 4: the holding is in arflex:list (HOLDING and the reason) and the DTO.</li>
 * </ul>
 * "Stopped" is every joint speed below {@link #STILL} rad/s; the bound on the time to stop is
 * generous (this machine is not PREEMPT_RT), the measured time is printed.
 */
class FailSafeIT {

    static final long T = CellRig.T;
    /** Joint speed under which the arm counts as stopped (rad/s). */
    static final double STILL = 2e-3;
    /** Time within which the arm must have stopped after its guard was killed (ms). */
    static final long STOP_MS = 1500;
    static final String PROGRAM = "arflex-program 1\n# FailSafeIT: base swing around the home pose\n"
            + "ptp 0.3 0.5 0.3 0 0.8 0 speed 0.1\nptp -0.3 0.5 0.3 0 0.8 0 speed 0.1\n";

    static void kill9(long pid) throws Exception {
        Signals.send(pid, "9");
    }

    /** A moving arm: robot, guard, correction stage and the trajectory looping program 1. */
    static List<String> movingCell(Runtime rt) throws Exception {
        Files.createDirectories(rt.dir.resolve("data"));
        Files.writeString(rt.dir.resolve("data/program-1.arp"), PROGRAM);
        List<String> cell = new java.util.ArrayList<>(CellRig.installArm(rt));
        rt.awaitState("ACTIVE", T, "sim-robot", "force-guard");
        // A stall of the runtime longer than the heartbeat timeout (issue 15 finding 6, not
        // solved on the Java side yet) latches the robot's reset; the operator resets it first.
        CellRig.resetBeforeTheTest(rt, "FailSafeIT");
        CellRig.startTrajectory(rt, 1, "loop", "true");
        cell.add("trajectory");
        rt.waitUntil("the arm follows the trajectory", T, () -> CellRig.armFollows(rt, "trajectory"));
        return cell;
    }

    static boolean moving(CellRig.Trace<CellRig.JointState> js) {
        CellRig.JointState j = js.last();
        return j != null && j.maxSpeed() > 10 * STILL;
    }

    /** The arm has been still for the last {@code n} values recorded. */
    static boolean stillFor(CellRig.Trace<CellRig.JointState> js, int n) {
        List<CellRig.JointState> s = js.snapshot();
        if (s.size() < n) {
            return false;
        }
        for (CellRig.JointState j : s.subList(s.size() - n, s.size())) {
            if (j.maxSpeed() > STILL) {
                return false;
            }
        }
        return true;
    }

    /**
     * Robot time (ms) from the last value recorded before a fault ({@code mark}: the trace's size
     * when the fault was injected) to the first value from which the arm stayed still up to the
     * newest value; -1 when the newest value is not still. Measured on the values themselves, not
     * on when a waiting loop noticed them.
     */
    static double stillAfterMs(CellRig.Trace<CellRig.JointState> js, int mark) {
        List<CellRig.JointState> s = js.snapshot();
        int first = s.size();
        while (first > mark && s.get(first - 1).maxSpeed() <= STILL) {
            first--;
        }
        if (first == s.size()) {
            return -1;
        }
        CellRig.JointState atFault = s.get(Math.max(0, mark - 1));
        return Math.max(0, (s.get(first).tNs() - atFault.tNs()) / 1e6);
    }

    static String holding(Runtime rt, String name) {
        Object h = rt.instance(name).get("holding");
        return h == null ? null : h.toString();
    }

    static String listLine(Runtime rt, String name) {
        return rt.cmd("arflex:list").lines().filter(l -> l.startsWith(name + " ")).findFirst().orElse("");
    }

    @Test
    void losingTheGuardStopsTheMovingArmUntilResetAndAFreshCommand() throws Exception {
        CellRig.assertBuilt(CellRig.SIM_ROBOT, CellRig.TRAJECTORY, CellRig.FORCE_GUARD);
        try (Runtime rt = new Runtime("failsafe-guard")) {
            movingCell(rt);
            CellRig.Trace<CellRig.JointState> js = new CellRig.Trace<>();
            try (CellRig.Port jp = new CellRig.Port(rt.segment("sim-robot", "joint_state"), CellRig.JOINT_STATE_SIZE);
                    CellRig.Recorder rec = new CellRig.Recorder()) {
                rec.add(jp, CellRig.JointState::of, CellRig.JointState::seq, js::add);
                rec.start();
                rt.waitUntil("the arm moving", T, () -> moving(js));
                assertNull(holding(rt, "sim-robot"), "holding before any fault");

                // Kill the guard four times, each 0.3 s after it is back (its restart intensity is 3).
                long pid = rt.pid("force-guard");
                kill9(pid);
                long killedNs = System.nanoTime();
                int mark = js.size();
                rt.waitUntil("the arm stopped after its guard was killed", T, () -> js.size() > mark && stillFor(js, 50));
                long stopMs = (System.nanoTime() - killedNs) / 1_000_000;
                double stillMs = stillAfterMs(js, mark);
                for (int k = 1; k < 4; k++) {
                    long old = pid;
                    rt.waitUntil("force-guard back (kill " + k + ")", T,
                            () -> rt.activeWithNewPid("force-guard", old) || "FAILED".equals(rt.state("force-guard")));
                    if ("FAILED".equals(rt.state("force-guard"))) {
                        break;
                    }
                    pid = rt.pid("force-guard");
                    long back = System.nanoTime();
                    rt.waitUntil("0.3 s after the restart", T, () -> System.nanoTime() - back > 300_000_000L);
                    kill9(pid);
                }
                rt.awaitState("FAILED", T, "force-guard");
                System.out.printf(java.util.Locale.ROOT, "FailSafeIT: arm still %.1f ms (robot time) after its guard was killed;"
                        + " seen by this test after %d ms (bound %d ms)%n", stillMs, stopMs, STOP_MS);
                assertTrue(stopMs <= STOP_MS, "the arm took " + stopMs + " ms to stop after losing its guard");

                // Stays stopped while the guard is FAILED, and says why.
                int held = js.size();
                rt.waitUntil("2000 robot cycles with the guard FAILED", T, () -> js.size() > held + 2000);
                double[] q0 = js.get(held).q();
                for (CellRig.JointState j : js.since(held)) {
                    assertTrue(CellRig.maxDiff(j.q(), q0) < 1e-3, "the arm moved without its guard: " + j);
                }
                String h = holding(rt, "sim-robot");
                assertTrue(h != null && h.contains("safety input 'safety'"), "sim-robot holding: " + h);
                assertTrue(listLine(rt, "sim-robot").contains("HOLDING"), rt.cmd("arflex:list"));
                String refused = rt.cmd("arflex:reset sim-robot");
                assertTrue(refused.contains("reset refused, the cause persists") && refused.contains("safety input"), refused);

                // The guard back, one cell reset: permitted, not started.
                assertTrue(rt.cmd("arflex:reset force-guard").contains("reset"));
                rt.awaitState("ACTIVE", T, "force-guard");
                rt.waitUntil("the guard permits again", T, () -> {
                    String x = holding(rt, "sim-robot");
                    return x == null || !x.contains("protective stop");
                });
                String cellReset = rt.cmd("arflex:reset --cell");
                assertTrue(cellReset.startsWith("cell: reset"), cellReset);
                rt.waitUntil("nothing awaits a reset", T, () -> CellRig.awaitingReset(rt).isEmpty());
                rt.waitUntil("trajectory waits for a fresh command", T,
                        () -> CellRig.awaitingCommand(rt).contains("trajectory"));
                int afterReset = js.size();
                rt.waitUntil("1000 robot cycles after the reset", T, () -> js.size() > afterReset + 1000);
                for (CellRig.JointState j : js.since(afterReset)) {
                    assertTrue(j.maxSpeed() <= STILL, "the arm moved after the reset without a command: " + j);
                }
                CellRig.set(rt, "trajectory", "run", "true");
                rt.waitUntil("the arm moves after the fresh command", T, () -> moving(js));
                assertNull(holding(rt, "sim-robot"));
                assertNull(holding(rt, "trajectory"));
                rec.close();
                assertNull(rec.error, String.valueOf(rec.error));
            }
        }
    }

    @Test
    void aRestartedMotionSourceWaitsForResetAndAFreshCommand() throws Exception {
        CellRig.assertBuilt(CellRig.SIM_ROBOT, CellRig.TRAJECTORY, CellRig.FORCE_GUARD);
        try (Runtime rt = new Runtime("failsafe-reset")) {
            movingCell(rt);
            CellRig.Trace<CellRig.JointState> js = new CellRig.Trace<>();
            try (CellRig.Port jp = new CellRig.Port(rt.segment("sim-robot", "joint_state"), CellRig.JOINT_STATE_SIZE);
                    CellRig.Recorder rec = new CellRig.Recorder()) {
                rec.add(jp, CellRig.JointState::of, CellRig.JointState::seq, js::add);
                rec.start();
                rt.waitUntil("the arm moving", T, () -> moving(js));
                long old = rt.pid("trajectory");
                kill9(old);
                rt.waitUntil("trajectory restarted", T, () -> rt.activeWithNewPid("trajectory", old));
                rt.waitUntil("the arm stopped", T, () -> stillFor(js, 50));
                assertTrue(listLine(rt, "trajectory").contains("HOLDING"), rt.cmd("arflex:list"));
                assertTrue(rt.cmd("arflex:reset trajectory").contains("reset"));
                rt.waitUntil("trajectory waits for a fresh command", T,
                        () -> CellRig.awaitingCommand(rt).contains("trajectory"));
                assertTrue(listLine(rt, "trajectory").contains("waits for a fresh command"), rt.cmd("arflex:list"));
                int afterReset = js.size();
                rt.waitUntil("1500 robot cycles after the reset", T, () -> js.size() > afterReset + 1500);
                for (CellRig.JointState j : js.since(afterReset)) {
                    assertTrue(j.maxSpeed() <= STILL, "the reset alone restarted motion: " + j);
                }
                CellRig.set(rt, "trajectory", "run", "true");
                rt.waitUntil("the arm moves after the fresh command", T, () -> moving(js));
                rec.close();
                assertNull(rec.error, String.valueOf(rec.error));
            }
        }
    }
}
