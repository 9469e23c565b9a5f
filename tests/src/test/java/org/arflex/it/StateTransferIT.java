package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertNotEquals;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.List;
import java.util.Locale;
import java.util.Map;
import java.util.concurrent.CompletableFuture;
import java.util.function.UnaryOperator;
import org.junit.jupiter.api.Test;

/**
 * docs/DECISIONS.md D41 through the real runtime, on the moving arm (FailSafeIT's looping
 * program; trajectory -> tcp-correction -> sim-robot): trajectory, the motion source, is updated
 * in a change set while the arm moves. Its contract declares a state block
 * (arflex.TrajectoryState 1.0); the new half adopts the old half's newest state at its START and
 * plays on from there: the same program, the same motion, the same limiter state.
 *
 * <p>What shows the transfer itself is not the robot's reference (tcp-correction fades a provider
 * change of up to 50 mrad, D35, which would hide a jump there) but (a) the step of
 * tcp-correction's input at the switch, the offset its fade took up, read from tcp-correction's
 * own state block: at most one cycle of the programmed motion; and (b) trajectory's own two
 * outputs: the new half continues the old one's seq and both write the same values under the
 * same seq. Without the state the same update cannot happen: a version that declares no state,
 * or another state type without a conversion, is refused by the plan with the reason and
 * nothing is spawned (cell.state_transfer shows the jump a fresh half would make: its program
 * from the start).
 *
 * <p>Versions made here from the trajectory bundle the build made, pinned: 1.0.1 (the same
 * executable and state block), 1.0.2-nostate (its contract without the state block),
 * 1.0.3-otherstate (arflex.TcpCorrectionState declared, no conversion).
 */
class StateTransferIT {

    static final long T = CellRig.T;
    static final String CONTRACT = "OSGI-INF/arflex/trajectory.xml";
    static final String STATE = "<state type=\"arflex.TrajectoryState\" typeVersion=\"1.0\"/>";
    /** One cycle of the program's fastest motion: speed 0.1 of joint 0's 123 deg/s over 1 ms, rad. */
    static final double ONE_CYCLE = 0.1 * CellRig.VMAX[0] * 1e-3;

    /**
     * arflex.TcpCorrectionState 1.0: its size and the offset of blend_offset[6] (contracts/types);
     * tcp-correction 1.1.0 publishes arflex.TcpCorrectionState2, which has these fields at the same
     * offsets (D52), so its first 368 bytes are read the same way.
     */
    static final int TCS_SIZE = 368; // TcpCorrectionStateLayout.SIZE (contracts: not on this classpath)
    static final int TCS_BLEND_OFFSET = 208; // TcpCorrectionStateLayout.OFFSET_BLEND_OFFSET

    /**
     * The offset tcp-correction took up at its last provider change, from its state block: its
     * last reference from the old provider minus its first from the new one (D35's fade starts
     * from it), i.e. the step of its input at the switch as the consumer saw it. Largest joint.
     */
    static double switchOffset(Runtime rt) throws IOException {
        try (CellRig.Port p = new CellRig.Port(Path.of("/dev/shm/arflex." + rt.rid + ".tcp-correction.state"),
                TCS_SIZE)) {
            java.nio.ByteBuffer b = p.read();
            assertTrue(b != null, "tcp-correction's state block");
            double m = 0;
            for (int i = 0; i < 6; i++) {
                m = Math.max(m, Math.abs(b.getDouble(TCS_BLEND_OFFSET + 8 * i)));
            }
            return m;
        }
    }

    /** A copy of the trajectory bundle with its contract's version set and {@code edit} applied to the contract. */
    static Path version(Path dir, String version, UnaryOperator<String> edit) throws IOException {
        return BundleCopies.copy(dir, CellRig.TRAJECTORY, "trajectory-" + version, Map.of(CONTRACT, BundleCopies.text(xml -> {
            assertTrue(xml.contains(STATE), "the built trajectory declares its state block");
            return edit.apply(xml.replaceFirst("name=\"trajectory\" version=\"[^\"]+\"",
                    "name=\"trajectory\" version=\"" + version + "\""));
        }, "the contract of trajectory " + version)));
    }

    /**
     * As {@link UpdateSetIT#crossSteps}, divided by the program steps between the two values (their
     * seqs, at least one) instead of the milliseconds between their stamps.
     */
    static double crossStepsBySeq(List<CellRig.Ref> from, List<CellRig.Ref> to) {
        java.util.TreeMap<Long, CellRig.Ref> byStamp = new java.util.TreeMap<>();
        for (CellRig.Ref r : to) {
            byStamp.put(r.tNs(), r);
        }
        double m = 0;
        for (CellRig.Ref a : from) {
            var next = byStamp.higherEntry(a.tNs());
            if (next != null && next.getKey() - a.tNs() < 5_000_000L) { // both ran then
                long steps = Math.max(1, Math.abs(next.getValue().seq() - a.seq()));
                m = Math.max(m, CellRig.maxDiff(a.q(), next.getValue().q()) / steps);
            }
        }
        return m;
    }

    @Test
    void trajectoryIsUpdatedOnTheMovingArmAndPlaysOnFromItsState() throws Exception {
        CellRig.assertBuilt(CellRig.SIM_ROBOT, CellRig.TRAJECTORY, CellRig.FORCE_GUARD, CellRig.TCP_CORRECTION);
        try (Runtime rt = new Runtime("state-transfer")) {
            List<String> cell = FailSafeIT.movingCell(rt);
            assertTrue(cell.contains("tcp-correction"), cell.toString());
            assertTrue(Files.exists(rt.segment("trajectory", "joint_ref").resolveSibling(
                    "arflex." + rt.rid + ".trajectory.state")), "trajectory's state segment");
            Path dir = Files.createDirectories(rt.dir.resolve("versions"));

            // without the state: refused by the plan, with the reason, nothing spawned
            Path none = version(dir, "1.0.2-nostate", x -> x.replace(STATE, ""));
            String refused = rt.cmd("arflex:change apply update trajectory file:" + none + " " + UpdateSetIT.sha256(none));
            System.out.println("StateTransferIT: a version without the state block:\n" + refused);
            assertTrue(refused.contains("refused: update trajectory file:" + none + ": state block: the running version "
                    + "1.0.0 hands over arflex.TrajectoryState 1.0, the new version 1.0.2-nostate declares no state and "
                    + "would start from nothing"), refused);
            Path other = version(dir, "1.0.3-otherstate", x -> x.replace(STATE,
                    "<state type=\"arflex.TcpCorrectionState\" typeVersion=\"1.0\"/>"));
            String refused2 = rt.cmd("arflex:change plan update trajectory file:" + other + " "
                    + UpdateSetIT.sha256(other));
            System.out.println("StateTransferIT: a version with another state type:\n" + refused2);
            assertTrue(refused2.contains("state block: the running version 1.0.0 hands over arflex.TrajectoryState 1.0, "
                    + "the new version 1.0.3-otherstate takes arflex.TcpCorrectionState 1.0 and declares no conversion "
                    + "from arflex.TrajectoryState 1.0"), refused2);
            assertTrue(Runtime.rtProcesses(rt.rid).stream().noneMatch(p -> p.contains("--instance 1-trajectory ")));
            assertTrue(!Files.exists(rt.segment("1-trajectory", "joint_ref")), "no segment of a refused set");

            // with the state: applied on the moving arm
            Path jar = version(dir, "1.0.1", x -> x);
            long robotPid = rt.pid("sim-robot");
            long guardPid = rt.pid("force-guard");
            long corrPid = rt.pid("tcp-correction");
            long oldPid = rt.pid("trajectory");
            CellRig.Trace<CellRig.Ref> oldOut = new CellRig.Trace<>();
            CellRig.Trace<CellRig.Ref> newOut = new CellRig.Trace<>();
            CellRig.Trace<CellRig.Ref> robotRef = new CellRig.Trace<>();
            CellRig.Trace<CellRig.JointState> js = new CellRig.Trace<>();
            CellRig.Trace<CellRig.Safety> safety = new CellRig.Trace<>();
            Path newSeg = rt.segment("1-trajectory", "joint_ref");
            try (CellRig.Port op = new CellRig.Port(rt.segment("trajectory", "joint_ref"), CellRig.REF_SIZE);
                    CellRig.Port rp = new CellRig.Port(rt.segment("tcp-correction", "corrected"), CellRig.REF_SIZE);
                    CellRig.Port jp = new CellRig.Port(rt.segment("sim-robot", "joint_state"), CellRig.JOINT_STATE_SIZE);
                    CellRig.Port sp = new CellRig.Port(rt.segment("force-guard", "safety"), CellRig.SAFETY_SIZE);
                    CellRig.Recorder rec = new CellRig.Recorder()) {
                rec.add(op, CellRig.Ref::of, CellRig.Ref::seq, oldOut::add);
                rec.add(rp, CellRig.Ref::of, CellRig.Ref::seq, robotRef::add);
                rec.add(jp, CellRig.JointState::of, CellRig.JointState::seq, js::add);
                rec.add(sp, CellRig.Safety::of, CellRig.Safety::seq, safety::add);
                rec.start();
                rt.waitUntil("the arm moving and 1000 references seen", T,
                        () -> FailSafeIT.moving(js) && oldOut.size() > 1000);
                Map<String, Object> robot0 = ChangeSetIT.stats(rt, "sim-robot");
                double offsetBefore = switchOffset(rt);
                int mark = oldOut.size();
                int robotMark = robotRef.size();
                int logMark = rt.logMark();
                long t0 = System.nanoTime();
                String pin = UpdateSetIT.sha256(jar);
                CompletableFuture<String> apply = CompletableFuture.supplyAsync(() -> rt.cmd(
                        "arflex:change apply update trajectory file:" + jar + " " + pin + " window 1000"));
                CellRig.Port np = null;
                try {
                    np = rec.recordRefsWhenItAppears(newSeg, apply, newOut::add);
                    String out = apply.get(T, java.util.concurrent.TimeUnit.MILLISECONDS);
                    long tookMs = (System.nanoTime() - t0) / 1_000_000;
                    List<String> log = rt.logSince(logMark);
                    System.out.println("StateTransferIT: apply (" + tookMs + " ms):\n" + out);
                    System.out.println("StateTransferIT: the runtime's log of the update:\n" + String.join("\n",
                            log.stream().filter(l -> l.contains("trajectory") && !l.contains("  ")).toList()));
                    assertTrue(out.contains("\napplied: ") && out.contains("update trajectory: committed"), out);
                    assertTrue(log.stream().anyMatch(l -> l.contains("1-trajectory") && l.contains(
                            "adopted the state block arflex.TrajectoryState 1.0 of /arflex." + rt.rid + ".trajectory.state")),
                            "the new half's adoption in the log");
                    assertTrue(np != null, "the new version's segment was never seen");
                    int after = robotRef.size();
                    rt.waitUntil("2000 references after the apply", T, () -> robotRef.size() > after + 2000);
                    assertNull(rec.error, () -> "recorder: " + rec.error);

                    // trajectory's own output across the two halves, and the program alone before
                    List<CellRig.Ref> o = oldOut.snapshot();
                    List<CellRig.Ref> n = newOut.snapshot();
                    assertTrue(n.size() > 1000, "values of the new half: " + n.size());
                    // at the switch: the values of both halves from 10 ms before the new half's first
                    // to 50 ms after it (the consumer's BIND follows its START in the same turn)
                    long s0 = n.get(0).tNs() - 10_000_000L;
                    long s1 = n.get(0).tNs() + 50_000_000L;
                    List<CellRig.Ref> ow = o.stream().filter(r -> r.tNs() >= s0 && r.tNs() <= s1).toList();
                    List<CellRig.Ref> nw = n.stream().filter(r -> r.tNs() <= s1).toList();
                    // per program step: trajectory advances one step per cycle it runs, so a half that
                    // skipped a release lags the other by a step in time (a CI run on a quiet machine:
                    // 0.392 mrad "per source cycle" by time, with the values under the same seq 10 urad
                    // apart); what each half wrote under a seq is the motion, and the seqs continue (both
                    // asserted below), so the step between the halves is counted per seq
                    double cross = Math.max(crossStepsBySeq(ow, nw), crossStepsBySeq(nw, ow));
                    double crossByTime = Math.max(UpdateSetIT.crossSteps(ow, nw), UpdateSetIT.crossSteps(nw, ow));
                    // over the whole window (both halves run on: a cycle one of them skips puts it a
                    // program step behind the other)
                    double crossAll = Math.max(UpdateSetIT.crossSteps(o, n), UpdateSetIT.crossSteps(n, o));
                    double offset = switchOffset(rt);
                    // the same motion: the new half continues the old one's seq, and the values both
                    // halves wrote under the same seq agree (a release one of them misses delays its
                    // next value, it does not change it; what differs is what each read of the
                    // guard and the arm at its own instant: micro-radians, bounded here by half a
                    // cycle of the programmed motion)
                    Map<Long, CellRig.Ref> bySeq = new java.util.HashMap<>();
                    for (CellRig.Ref r : o) {
                        bySeq.put(r.seq(), r);
                    }
                    int same = 0;
                    double sameDiff = 0;
                    for (CellRig.Ref r : n) {
                        CellRig.Ref a = bySeq.get(r.seq());
                        if (a != null) {
                            same++;
                            sameDiff = Math.max(sameDiff, CellRig.maxDiff(a.q(), r.q()));
                        }
                    }
                    double before = 0;
                    for (int i = 1; i < mark; i++) {
                        before = Math.max(before, ChangeSetIT.perSourceCycle(o.get(i - 1), o.get(i)));
                    }
                    // the new half's first value against the old half's value of the same stamp or the one before
                    CellRig.Ref first = n.get(0);
                    CellRig.Ref prior = o.stream().filter(r -> r.tNs() <= first.tNs()).reduce((a, b) -> b).orElseThrow();
                    double firstStep = ChangeSetIT.perSourceCycle(prior, first);
                    double[] robotSteps = CellRig.stepsBeforeAndAfter(robotRef.snapshot(), robotMark);
                    double robotBefore = robotSteps[0];
                    double robotAfter = robotSteps[1];
                    List<CellRig.Safety> ss = safety.snapshot();
                    CellRig.Safety worst = CellRig.worst(ss);
                    CellRig.Safety tripped = CellRig.tripped(ss);
                    Map<String, Object> robot1 = ChangeSetIT.stats(rt, "sim-robot");
                    System.out.printf(Locale.ROOT, "StateTransferIT: the new half's first seq %d (the old half's "
                            + "last before the apply %d); %d values written by both halves under the same seq, largest "
                            + "difference %.3g rad%n", n.get(0).seq(), o.get(mark - 1).seq(), same, sameDiff);
                    System.out.printf(Locale.ROOT, "StateTransferIT: the step of tcp-correction's input at the switch "
                            + "(the offset it took up, from its state block): %.3f mrad (%.3f before the apply; bound, "
                            + "two cycles of the programmed motion: %.3f); between the two halves over the whole window: "
                            + "%.3f mrad per source cycle%n", offset * 1e3, offsetBefore * 1e3, 2 * ONE_CYCLE * 1e3,
                            crossAll * 1e3);
                    System.out.printf(Locale.ROOT, "StateTransferIT: trajectory's own output across the two halves at the switch: "
                            + "largest step %.3f mrad per program step (%.3f per ms; bound, one cycle of the programmed motion: "
                            + "%.3f; the program alone before the apply: %.3f); the new half's first value %.3f mrad "
                            + "per source cycle from the old half's value before it (%.3f ms apart); %d values of the "
                            + "new half; the robot's reference: %.3f mrad per source cycle from the apply on (%.3f "
                            + "before; bound %.3f); largest force the guard read %.1f N; sim-robot %d safe cycles; "
                            + "command %d ms%n", cross * 1e3, crossByTime * 1e3, ONE_CYCLE * 1e3, before * 1e3, firstStep * 1e3,
                            (first.tNs() - prior.tNs()) / 1e6, n.size(), robotAfter * 1e3, robotBefore * 1e3,
                            ChangeSetIT.JUMP_BOUND * 1e3, worst.forceNorm(), ChangeSetIT.delta(robot0, robot1,
                            "safeCycles"), tookMs);
                    // the switch's discontinuity: trajectory's output across its two halves, per source
                    // cycle (a release either half skips does not count as a step)
                    assertTrue(cross <= ONE_CYCLE * 1.02, "trajectory's output stepped " + cross
                            + " rad per program step across the two halves at the switch");
                    // what tcp-correction took up: its last value of the old half and its first of the
                    // new one, read at two instants; when the old half had skipped a release just
                    // before (under load: 0.26-0.31 mrad in a third of the runs with builds beside
                    // them), those are two source cycles apart, not one
                    assertTrue(offset <= 2 * ONE_CYCLE * 1.02, "tcp-correction's reference stepped " + offset
                            + " rad at the switch");
                    assertTrue(same > 500, "values under the same seq: " + same);
                    assertTrue(sameDiff < ONE_CYCLE / 2, "the two halves differ by " + sameDiff + " rad under the same seq");
                    assertTrue(n.get(0).seq() > o.get(mark - 1).seq(), "the new half continues the old one's seq");
                    assertTrue(robotAfter <= ChangeSetIT.JUMP_BOUND, "robot reference step " + robotAfter);
                    assertNull(tripped, "the guard left NORMAL: " + tripped);
                    assertEquals(0, ChangeSetIT.delta(robot0, robot1, "safeCycles"), "sim-robot ran safe cycles");
                    int robotFlags = CellPorts.ctlFlags(Path.of("/dev/shm/arflex." + rt.rid + ".sim-robot.ctl"));
                    assertEquals(0, robotFlags & CellPorts.FLAG_SAFE_ACTIVE, "sim-robot in safe mode");
                    assertEquals(List.of(), CellRig.awaitingReset(rt));
                    assertEquals(List.of(), CellRig.awaitingCommand(rt));
                    assertNull(FailSafeIT.holding(rt, "sim-robot"));
                    assertEquals(robotPid, rt.pid("sim-robot"));
                    assertEquals(guardPid, rt.pid("force-guard"));
                    assertEquals(corrPid, rt.pid("tcp-correction"));
                } finally {
                    if (np != null) {
                        np.close();
                    }
                }
            }
            rt.awaitState("ACTIVE", T, "trajectory", "tcp-correction", "sim-robot", "force-guard");
            assertNotEquals(oldPid, rt.pid("trajectory"), "the new version runs");
            assertEquals(0, ((Number) rt.instance("trajectory").get("restarts")).intValue());
            assertTrue(rt.cmd("arflex:info trajectory").contains("1.0.1"), rt.cmd("arflex:info trajectory"));
            assertTrue(CellRig.armFollows(rt, "trajectory"), rt.cmd("arflex:bindings"));
            rt.waitUntil("the old version's process, segments and state segment gone", T, () -> Runtime.rtProcesses(
                    rt.rid).stream().noneMatch(p -> p.contains("--instance trajectory ")) && !Files.exists(
                    rt.segment("trajectory", "joint_ref")) && !Files.exists(Path.of("/dev/shm/arflex." + rt.rid
                    + ".trajectory.state")));
            assertTrue(Files.exists(Path.of("/dev/shm/arflex." + rt.rid + ".1-trajectory.state")),
                    "the new half publishes its state block");
        }
    }
}
