package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertNotNull;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.ArrayList;
import java.util.Arrays;
import java.util.List;
import org.junit.jupiter.api.Test;

/**
 * Force guard through the real runtime (issue 7): the arm (sim-robot) plays the trajectory's
 * built-in program in a loop, force-guard watches its joint torques and wrist wrench. A scripted
 * push above the threshold ({@code arflex:set sim-robot push_force_n 400}) puts the cell in a
 * protective stop in the cycle that reads it: no SafetyState value ever shows a contact force
 * above the limit in NORMAL mode, and the first PROTECTIVE_STOP comes at most three guard periods
 * after the push shows in the wrist sensor (cycle timestamps of the two RT halves, not the
 * test's clock: the same or the next guard cycle is two periods, and the stamps are write times,
 * so the two tasks' wake-up latency adds; one period is allowed for it, see the assertion). The trajectory then decelerates along its path and its joint_ref stays
 * bit-identical for more than 1000 of its cycles, through the end of the push, until the
 * operator's {@code arflex:reset force-guard}; the motion resumes only after a fresh command
 * ({@code arflex:set trajectory run true}): a reset permits, it does not start (issue 15). The robot's drives take
 * the guard's power limit: sim-robot's {@code servo_power} is 1 while NORMAL, drops to the
 * guard's {@code safe_power_fraction} in the same or the next robot cycle after the stop, and is
 * 1 again after the reset.
 */
class ForceGuardIT {

    static final long T = CellRig.T;
    static final double PUSH_N = 400;
    static final String PROGRAM = "arflex-program 1\n# ForceGuardIT: base swing around the home pose\n"
            + "ptp 0.3 0.5 0.3 0 0.8 0 speed 0.1\nptp -0.3 0.5 0.3 0 0.8 0 speed 0.1\n";

    @Test
    void pushStopsTheCellUntilTheOperatorResets() throws Exception {
        CellRig.assertBuilt(CellRig.SIM_ROBOT, CellRig.TRAJECTORY, CellRig.FORCE_GUARD);
        try (Runtime rt = new Runtime("forceguard")) {
            List<String> cell = new ArrayList<>(CellRig.installArm(rt));
            // The motion: a program file in the runtime's data directory (<runtime>/data, where
            // the RT halves' working directory is): the base swings +-0.3 rad around the home
            // pose and back, in a loop. Not the built-in program: the simulated arm's drives
            // cannot follow its first joint motion (joint 2 saturates and crawls at about
            // 0.19 rad/s, then stops abruptly: 170-410 N at the wrist, which the guard rightly
            // reads as contact; bundles/force-guard/README.md).
            java.nio.file.Files.createDirectories(rt.dir.resolve("data"));
            java.nio.file.Files.writeString(rt.dir.resolve("data/program-1.arp"), PROGRAM);
            rt.awaitState("ACTIVE", T, "sim-robot", "force-guard");
            rt.installAndStart(CellRig.TRAJECTORY);
            cell.add("trajectory");
            rt.awaitState("ACTIVE", T, cell.toArray(String[]::new));
            CellRig.set(rt, "trajectory", "loop", "true");
            rt.waitUntil("the arm follows the trajectory", T, () -> CellRig.armFollows(rt, "trajectory"));
            String b = rt.cmd("arflex:bindings");
            assertTrue(b.contains("trajectory.safety <- force-guard.safety"), b);
            assertTrue(b.contains("force-guard.wrench <- sim-robot.wrench"), b);
            assertTrue(b.contains("force-guard.joint_state <- sim-robot.joint_state"), b);
            assertTrue(b.contains("sim-robot.safety <- force-guard.safety"), b);
            long guardPid = rt.pid("force-guard");
            long trajPid = rt.pid("trajectory");

            CellRig.Trace<CellRig.Safety> safetyT = new CellRig.Trace<>();
            CellRig.Trace<CellRig.Wrench> wrenchT = new CellRig.Trace<>();
            CellRig.Trace<CellRig.Ref> refT = new CellRig.Trace<>();
            CellRig.Trace<CellRig.JointState> jsT = new CellRig.Trace<>();
            CellRig.Trace<CellRig.Ref> armRefT = new CellRig.Trace<>();
            CellRig.Trace<CellRig.Sample> powerT = new CellRig.Trace<>();
            // what the arm is told to follow (tcp-correction's output when the cell has one)
            String armSource = cell.contains("tcp-correction") ? "tcp-correction" : "trajectory";
            String armPort = cell.contains("tcp-correction") ? "corrected" : "joint_ref";
            try (CellRig.Port sp = new CellRig.Port(rt.segment("force-guard", "safety"), CellRig.SAFETY_SIZE);
                    CellRig.Port wp = new CellRig.Port(rt.segment("sim-robot", "wrench"), CellRig.WRENCH_SIZE);
                    CellRig.Port rp = new CellRig.Port(rt.segment("trajectory", "joint_ref"), CellRig.REF_SIZE);
                    CellRig.Port jp = new CellRig.Port(rt.segment("sim-robot", "joint_state"), CellRig.JOINT_STATE_SIZE);
                    CellRig.Port ap = new CellRig.Port(rt.segment(armSource, armPort), CellRig.REF_SIZE);
                    CellRig.Port pp = new CellRig.Port(rt.segment("sim-robot", "servo_power"), CellRig.SAMPLE_SIZE);
                    CellRig.Recorder rec = new CellRig.Recorder()) {
                rec.add(sp, CellRig.Safety::of, CellRig.Safety::seq, safetyT::add);
                rec.add(wp, CellRig.Wrench::of, CellRig.Wrench::seq, wrenchT::add);
                rec.add(rp, CellRig.Ref::of, CellRig.Ref::seq, refT::add);
                rec.add(jp, CellRig.JointState::of, CellRig.JointState::seq, jsT::add);
                rec.add(ap, CellRig.Ref::of, CellRig.Ref::seq, armRefT::add);
                rec.add(pp, CellRig.Sample::of, CellRig.Sample::seq, powerT::add);
                rec.start();

                // Moving, in NORMAL mode, for a while (no false trip from the motion itself).
                try {
                    scenario(rt, safetyT, wrenchT, refT, powerT, rec, guardPid, trajPid);
                } catch (AssertionError | RuntimeException e) {
                    for (String n : new String[] {"sim-robot", "tcp-correction", "force-guard", "trajectory"}) {
                        System.out.println("ForceGuardIT: " + rt.cmd("arflex:stats " + n).replace('\n', ' '));
                    }
                    dump(rt, safetyT.snapshot(), refT.snapshot(), wrenchT.snapshot(), jsT.snapshot(), armRefT.snapshot());
                    throw e;
                }
            }
        }
    }

    static void scenario(Runtime rt, CellRig.Trace<CellRig.Safety> safetyT, CellRig.Trace<CellRig.Wrench> wrenchT,
            CellRig.Trace<CellRig.Ref> refT, CellRig.Trace<CellRig.Sample> powerT, CellRig.Recorder rec, long guardPid,
            long trajPid) throws Exception {
                rt.waitUntil("1500 guard values and the arm moving", T,
                        () -> safetyT.size() > 1500 && (moved(refT.snapshot())
                                || safetyT.last().mode() != CellRig.Safety.NORMAL));
                CellRig.Safety before = safetyT.last();
                assertTrue((before.flags() & 0x2) == 0, "the runtime heartbeat was lost (a stall of the runtime longer than"
                        + " the 100 ms heartbeat timeout): the cell is in safe mode for that reason, not a push: " + before);
                assertEquals(CellRig.Safety.NORMAL, before.mode(),
                        "the guard tripped without a push: " + before + "; max force seen "
                                + safetyT.snapshot().stream().mapToDouble(CellRig.Safety::forceNorm).max().orElse(0));
                double limit = before.forceLimit();
                double maxFree = safetyT.snapshot().stream().mapToDouble(CellRig.Safety::forceNorm).max().orElse(0);
                int wrenchMark = wrenchT.size();

                // The push: 400 N along +y on the TCP for 200 ms of simulated time.
                CellRig.set(rt, "sim-robot", "push_duration_ms", "200");
                CellRig.set(rt, "sim-robot", "push_force_n", Double.toString(PUSH_N));
                rt.waitUntil("PROTECTIVE_STOP", T, () -> safetyT.last().mode() == CellRig.Safety.PROTECTIVE_STOP);

                // The push ends by itself (200 ms): the guard reads the force below the limit
                // again, and stays latched.
                rt.waitUntil("the push over (guard reads the force below the limit)", T, () -> {
                    CellRig.Safety s = safetyT.last();
                    return s.mode() == CellRig.Safety.PROTECTIVE_STOP && s.forceNorm() < limit
                            && pushSeen(safetyT.snapshot(), limit);
                });
                long pushOverNs = safetyT.last().tNs();
                // The reference holds, bit for bit, for more than 1000 trajectory cycles that
                // extend past the end of the push.
                rt.waitUntil("joint_ref constant over 1000 cycles after the push ended", T, () -> {
                    List<CellRig.Ref> refs = refT.snapshot();
                    long[] run = constantRun(refs);
                    return run != null && run[1] - run[0] > 1000 && refs.get(refs.size() - 1).tNs() > pushOverNs;
                });
                CellRig.Safety stillStopped = safetyT.last();
                assertEquals(CellRig.Safety.PROTECTIVE_STOP, stillStopped.mode(), "left the stop without a reset");
                assertTrue((stillStopped.flags() & 0x4) != 0, "RESET_REQUIRED not set: " + stillStopped);
                long[] held = constantRun(refT.snapshot());
                assertNotNull(held);
                double[] heldQ = refT.last().q().clone();
                // The drives limited to the guard's fraction while stopped.
                double fraction = stillStopped.powerScale();
                assertTrue(fraction < 1.0, "the stop publishes no reduced power: " + stillStopped);
                rt.waitUntil("sim-robot's servo_power at the guard's fraction", T,
                        () -> powerT.size() > 0 && powerT.last().value() == fraction);
                int refMark = refT.size();

                // While stopped the shell and the DTO say so: HOLDING, with the guard named.
                String list = rt.cmd("arflex:list");
                assertTrue(list.lines().anyMatch(l -> l.startsWith("trajectory") && l.contains("HOLDING")
                        && l.contains("safety input 'safety' in a protective stop (provider force-guard")), list);
                // Operator reset: NORMAL again; the reset permits motion, it does not start it.
                String r = rt.cmd("arflex:reset force-guard");
                assertTrue(r.startsWith("force-guard: reset"), r);
                rt.waitUntil("NORMAL after the reset", T, () -> safetyT.last().mode() == CellRig.Safety.NORMAL);
                rt.waitUntil("full servo power after the reset", T, () -> powerT.last().value() == 1.0);
                rt.waitUntil("trajectory holding for a fresh command", T, () -> String.valueOf(
                        rt.instance("trajectory").get("holding")).startsWith("stopped: waits for a fresh command"));
                int afterReset = refT.size();
                rt.waitUntil("500 trajectory cycles after the reset", T, () -> refT.size() > afterReset + 500);
                for (CellRig.Ref x : refT.since(afterReset)) {
                    assertTrue(Arrays.equals(x.q(), heldQ), "the motion resumed after the reset without a command: " + x);
                }
                // The fresh command.
                CellRig.set(rt, "trajectory", "run", "true");
                rt.waitUntil("the motion resumes", T,
                        () -> refT.size() > refMark && CellRig.maxDiff(refT.last().q(), heldQ) > 1e-3);
                assertEquals(guardPid, rt.pid("force-guard"), "the guard was restarted");
                assertEquals(trajPid, rt.pid("trajectory"), "the trajectory was restarted");
                rec.close();
                assertNull(rec.error, String.valueOf(rec.error));
                List<CellRig.Safety> safety = safetyT.snapshot();
                List<CellRig.Wrench> wrench = wrenchT.snapshot();
                List<CellRig.Ref> refs = refT.snapshot();
                List<CellRig.Sample> power = powerT.snapshot();

                // ---- analysis of what was recorded ----
                // (a) Never a contact force above the limit in NORMAL mode: the trip is in the
                // cycle that reads the force.
                for (CellRig.Safety s : safety) {
                    assertTrue(!(s.mode() == CellRig.Safety.NORMAL && s.forceNorm() > s.forceLimit()),
                            "NORMAL with a contact force above the limit: " + s);
                }
                // (b) The first stop, and whether the value before it was seen too.
                int k = -1;
                for (int i = 0; i < safety.size(); i++) {
                    if (safety.get(i).mode() == CellRig.Safety.PROTECTIVE_STOP) {
                        k = i;
                        break;
                    }
                }
                assertTrue(k > 0, "no stop recorded");
                CellRig.Safety stop = safety.get(k);
                boolean exact = safety.get(k - 1).seq() == stop.seq() - 1;
                assertTrue(stop.forceNorm() > limit, "the first stop value does not carry the force that tripped it: " + stop);
                // (c) The push as the wrist sensor shows it: the first wrench value after the
                // `set` whose magnitude moved more than 50 N from the pre-push median (the
                // free motion reads a few newtons).
                double[] band = wrench.subList(Math.max(0, wrenchMark - 500), wrenchMark).stream()
                        .mapToDouble(CellRig.Wrench::norm).sorted().toArray();
                double median = band[band.length / 2];
                int w = -1;
                for (int i = wrenchMark; i < wrench.size(); i++) {
                    if (Math.abs(wrench.get(i).norm() - median) > 50) {
                        w = i;
                        break;
                    }
                }
                assertTrue(w > 0, "the push never showed in the wrist sensor");
                CellRig.Wrench onset = wrench.get(w);
                boolean onsetExact = wrench.get(w - 1).seq() == onset.seq() - 1;
                double periods = (stop.tNs() - onset.tNs()) / 1e6;
                long stopRun = held[1] - held[0];
                // The hold began once the trajectory had decelerated along its path (stop_time
                // 0.3 s of its cycles) and lasted to the reset.
                long heldFromNs = refs.stream().filter(x -> x.seq() == held[0]).findFirst().orElseThrow().tNs();
                double decel = (heldFromNs - stop.tNs()) / 1e9;
                System.out.printf("ForceGuardIT: from the first stop to the held reference %.3f s (trajectory cycles);"
                        + " push over %.3f s after the stop%n", decel, (pushOverNs - stop.tNs()) / 1e9);
                assertTrue(decel < 0.5, "the trajectory took " + decel + " s of its cycles to stop");
                System.out.printf("ForceGuardIT: limit %.0f N; largest contact force while moving freely %.1f N; push %.0f N%n",
                        limit, maxFree, PUSH_N);
                System.out.printf("ForceGuardIT: push onset in the wrist sensor (robot seq %d%s) -> first PROTECTIVE_STOP"
                        + " (guard seq %d, force %.1f N%s): %.2f guard periods (cycle timestamps)%n", onset.seq(),
                        onsetExact ? ", previous value seen" : ", a value before it was missed", stop.seq(),
                        stop.forceNorm(), exact ? ", the NORMAL value of the cycle before seen" : "", periods);
                System.out.printf("ForceGuardIT: joint_ref held bit-identical over %d trajectory cycles (seq %d..%d);"
                        + " %d safety, %d wrench, %d joint_ref values recorded%n", stopRun, held[0], held[1], safety.size(),
                        wrench.size(), refs.size());
                // Same or next cycle: the guard's stop is at most two of its periods after the
                // release of the robot cycle that measured the push (phase between the two
                // tasks up to one period). The stamps are write times, so each task's wake-up
                // latency adds to them: on this non-PREEMPT_RT kernel a loaded machine showed
                // 2.04 periods once. One period of slack for that; the figure itself is printed
                // above and measured by the benchmarks.
                assertTrue(periods <= 3.0, "first stop " + periods + " periods after the push onset " + onset + " / " + stop
                        + " (onset exact: " + onsetExact + ")");
                // (d) The power limit reaches the drives in the same or the next robot cycle
                // after the guard's decision (robot sequence numbers: one per physics period),
                // and full power before it.
                CellRig.Sample firstAfter = power.stream().filter(x -> x.tNs() > stop.tNs()).findFirst().orElseThrow();
                CellRig.Sample firstLimited = power.stream().filter(x -> x.value() < 1.0).findFirst().orElseThrow();
                for (CellRig.Sample x : power) {
                    assertTrue(x.value() == 1.0 || x.value() == stop.powerScale(), "servo power neither full nor the"
                            + " guard's fraction: " + x);
                    if (x.tNs() <= stop.tNs() - 1_000_000) {
                        assertEquals(1.0, x.value(), "reduced power before the stop: " + x);
                    }
                }
                System.out.printf("ForceGuardIT: servo power %.2f from robot cycle %d; first robot cycle released after the"
                        + " stop: %d%n", firstLimited.value(), firstLimited.seq(), firstAfter.seq());
                assertTrue(firstLimited.seq() <= firstAfter.seq() + 1, "the power limit reached the drives at robot cycle "
                        + firstLimited.seq() + ", the first released after the stop was " + firstAfter.seq());
    }

    /** Writes the recorded traces to the test's directory (diagnosis of a failure). */
    static void dump(Runtime rt, List<CellRig.Safety> s, List<CellRig.Ref> r, List<CellRig.Wrench> w,
            List<CellRig.JointState> js, List<CellRig.Ref> armRef) throws java.io.IOException {
        StringBuilder sb = new StringBuilder("kind,t_ns,seq,a,b,c,d,e,f\n");
        for (CellRig.Safety x : s) {
            sb.append("safety,").append(x.tNs()).append(',').append(x.seq()).append(',').append(x.mode()).append(',')
                    .append(x.forceNorm()).append(',').append(x.flags()).append('\n');
        }
        for (CellRig.Ref x : r) {
            sb.append("ref,").append(x.tNs()).append(',').append(x.seq());
            for (double v : x.q()) {
                sb.append(',').append(v);
            }
            sb.append('\n');
        }
        for (CellRig.Wrench x : w) {
            sb.append("wrench,").append(x.tNs()).append(',').append(x.seq());
            for (double v : x.force()) {
                sb.append(',').append(v);
            }
            sb.append('\n');
        }
        for (CellRig.JointState x : js) {
            sb.append("js,").append(x.tNs()).append(',').append(x.seq());
            for (double v : x.q()) {
                sb.append(',').append(v);
            }
            sb.append('\n');
        }
        for (CellRig.Ref x : armRef) {
            sb.append("armref,").append(x.tNs()).append(',').append(x.seq());
            for (double v : x.q()) {
                sb.append(',').append(v);
            }
            sb.append('\n');
        }
        java.nio.file.Path out = rt.dir.getParent().resolve("forceguard-trace.csv");
        java.nio.file.Files.writeString(out, sb);
        System.out.println("ForceGuardIT: traces in " + out);
    }

    static boolean moved(List<CellRig.Ref> refs) {
        return refs.size() > 100 && CellRig.maxDiff(refs.get(0).q(), refs.get(refs.size() - 1).q()) > 1e-3;
    }

    static boolean pushSeen(List<CellRig.Safety> s, double limit) {
        return s.stream().anyMatch(x -> x.forceNorm() > limit);
    }

    /** First and last seq of the trailing run of bit-identical joint_ref values, or null. */
    static long[] constantRun(List<CellRig.Ref> refs) {
        int n = refs.size();
        if (n < 2) {
            return null;
        }
        double[] q = refs.get(n - 1).q();
        int i = n - 1;
        while (i > 0 && Arrays.equals(refs.get(i - 1).q(), q)) {
            i--;
        }
        return new long[] {refs.get(i).seq(), refs.get(n - 1).seq()};
    }
}
