package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertNotEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.HashMap;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Locale;
import java.util.Map;
import java.util.function.UnaryOperator;
import org.junit.jupiter.api.Test;

/**
 * docs/DECISIONS.md D52 through the real runtime, on the moving arm (FailSafeIT's looping
 * program; trajectory -> tcp-correction -> sim-robot): a declared state conversion executed.
 * The cell runs tcp-correction 1.0.5, made here from the built bundle with a 1.0 contract (state
 * block arflex.TcpCorrectionState 1.0, no blend_time parameter), deployed pinned. It is updated
 * in a change set, while the arm moves, to the built bundle itself, 1.1.0, whose state block is
 * arflex.TcpCorrectionState2 with {@code <convertsFrom type="arflex.TcpCorrectionState"
 * typeVersion="1.0"/>}: the new half adopts the old half's 1.0 block through its conversion
 * (the fade's duration, which 1.0 did not record, is 1.0's fixed 0.5 s).
 *
 * <p>Asserted: committed, the new half's log says it adopted the 1.0 block; no safe stop, no
 * reset, the guard NORMAL (UpdateSetIT's checks); the robot's reference across the two halves at
 * most one cycle of the programmed motion per source cycle, and for every reference stamp both
 * halves passed on, the same value (the same correction continued); the converted field: with
 * blend_time set to 0.2 s afterwards, the new half's state block still says blend_duration 0.5
 * (nothing but the conversion wrote 0.5 there). Then the way back is refused by the plan with
 * its reason: 1.0.5 takes the 1.0 block and declares no conversion from TcpCorrectionState2.
 */
class StateConversionIT {

    static final long T = CellRig.T;
    static final String CONTRACT = UpdateSetIT.CONTRACT;
    static final String V1_STATE = "<state type=\"arflex.TcpCorrectionState\" typeVersion=\"1.0\"/>";
    /** One cycle of the program's fastest motion: speed 0.1 of joint 0's 123 deg/s over 1 ms, rad. */
    static final double ONE_CYCLE = StateTransferIT.ONE_CYCLE;
    /** arflex.TcpCorrectionState2 1.0: its size and the offset of blend_duration (contracts/types). */
    static final int TCS2_SIZE = 376; // TcpCorrectionState2Layout.SIZE (contracts: not on this classpath)
    static final int TCS2_BLEND_DURATION = 368; // TcpCorrectionState2Layout.OFFSET_BLEND_DURATION

    /** tcp-correction 1.0.5: the built bundle under a 1.0 contract (the 1.0 state block, no blend_time). */
    static Path oldVersion(Path dir) throws IOException {
        Map<String, UnaryOperator<byte[]>> edits = new LinkedHashMap<>();
        edits.put(CONTRACT, BundleCopies.text(xml -> {
            assertTrue(xml.contains("arflex.TcpCorrectionState2") && xml.contains("name=\"blend_time\""),
                    "the built tcp-correction declares TcpCorrectionState2 and blend_time");
            return xml.replaceFirst("name=\"tcp-correction\" version=\"[^\"]+\"", "name=\"tcp-correction\" version=\"1.0.5\"")
                    .replaceFirst("(?s)<state type=\"arflex.TcpCorrectionState2\".*?</state>", V1_STATE)
                    .replaceFirst("\\s*<property name=\"blend_time\"[^>]*>[^<]*</property>", "");
        }, "the contract of tcp-correction 1.0.5"));
        edits.put("META-INF/MANIFEST.MF", BundleCopies.text(mf -> mf.replaceFirst("Bundle-Version: [^\r\n]+",
                "Bundle-Version: 1.0.5"), "the manifest's Bundle-Version"));
        return BundleCopies.copy(dir, CellRig.TCP_CORRECTION, "tcp-correction-1.0.5", edits);
    }

    /** The double at {@code offset} of the newest value of {@code id}'s state block. */
    static double stateField(Runtime rt, String id, int offset) throws IOException {
        try (CellRig.Port p = new CellRig.Port(Path.of("/dev/shm/arflex." + rt.rid + "." + id + ".state"), TCS2_SIZE)) {
            java.nio.ByteBuffer b = p.read();
            assertTrue(b != null, id + "'s state block");
            return b.getDouble(offset);
        }
    }

    @Test
    void tcpCorrectionConvertsTheOldVersionsStateOnTheMovingArm() throws Exception {
        CellRig.assertBuilt(CellRig.SIM_ROBOT, CellRig.TRAJECTORY, CellRig.FORCE_GUARD, CellRig.TCP_CORRECTION);
        try (Runtime rt = new Runtime("state-conversion")) {
            Path dir = Files.createDirectories(rt.dir.resolve("versions"));
            Path old = oldVersion(dir);
            // the moving arm of FailSafeIT.movingCell, its tcp-correction the 1.0 version
            Files.createDirectories(rt.dir.resolve("data"));
            Files.writeString(rt.dir.resolve("data/program-1.arp"), FailSafeIT.PROGRAM);
            rt.installAndStart(CellRig.SIM_ROBOT);
            rt.installAndStart(CellRig.FORCE_GUARD);
            String deployed = rt.cmd("arflex:deploy " + old.toUri() + " " + UpdateSetIT.sha256(old));
            assertTrue(!deployed.contains("error") && !deployed.contains("refused"), "deploy: " + deployed);
            rt.awaitState("ACTIVE", T, "sim-robot", "force-guard"); // tcp-correction waits for a motion source
            CellRig.resetBeforeTheTest(rt, "StateConversionIT");
            CellRig.startTrajectory(rt, 1, "loop", "true");
            rt.awaitState("ACTIVE", T, "tcp-correction", "trajectory");
            assertTrue(rt.cmd("arflex:info tcp-correction").startsWith("tcp-correction 1.0.5 "),
                    rt.cmd("arflex:info tcp-correction"));
            rt.waitUntil("the arm follows the trajectory", T, () -> CellRig.armFollows(rt, "trajectory"));

            // 1.0.5 -> 1.1.0 (the built bundle) on the moving arm
            int logMark = rt.logMark();
            List<CellRig.Ref> oldOut = new ArrayList<>();
            List<CellRig.Ref> newOut = new ArrayList<>();
            UpdateSetIT.Run r = UpdateSetIT.update(rt, CellRig.TCP_CORRECTION, "window 1000", (o, n) -> {
                oldOut.addAll(o);
                newOut.addAll(n);
            });
            List<String> log = rt.logSince(logMark);
            assertTrue(r.out().contains("update tcp-correction: committed: the new version ran"), r.out());
            String adopted = "adopted the state block arflex.TcpCorrectionState 1.0 of /arflex." + rt.rid
                    + ".tcp-correction.state";
            assertTrue(log.stream().anyMatch(l -> l.contains("1-tcp-correction") && l.contains(adopted)),
                    "the new half's adoption of the 1.0 block in the log:\n" + String.join("\n", log));
            // the same reference stamp passed on by both halves: the same value (the correction
            // continued; a fresh half would start without it, a wrong fade would differ)
            Map<Long, CellRig.Ref> byStamp = new HashMap<>();
            for (CellRig.Ref o : oldOut) {
                byStamp.put(o.tNs(), o);
            }
            int same = 0;
            double sameDiff = 0;
            for (CellRig.Ref n : newOut) {
                CellRig.Ref o = byStamp.get(n.tNs());
                if (o != null) {
                    same++;
                    sameDiff = Math.max(sameDiff, CellRig.maxDiff(o.q(), n.q()));
                }
            }
            rt.awaitState("ACTIVE", T, "tcp-correction", "sim-robot", "force-guard", "trajectory");
            assertEquals(0, ((Number) rt.instance("tcp-correction").get("restarts")).intValue());
            assertNotEquals(r.oldPid(), rt.pid("tcp-correction"), "the new version runs");
            assertTrue(rt.cmd("arflex:info tcp-correction").startsWith("tcp-correction 1.1.0 "),
                    rt.cmd("arflex:info tcp-correction"));

            // the converted field: 1.0's fade duration, whatever the parameter says now
            String set = rt.cmd("arflex:set tcp-correction blend_time 0.2");
            String get = rt.cmd("arflex:get tcp-correction blend_time");
            assertTrue(get.contains("0.2"), "blend_time after the set (" + set + "): " + get);
            double duration = stateField(rt, "1-tcp-correction", TCS2_BLEND_DURATION);
            System.out.printf(Locale.ROOT, "StateConversionIT: %s; the robot's reference between the versions: %.3f "
                    + "mrad per source cycle (bound, one cycle of the programmed motion: %.3f; the program alone "
                    + "before: %.3f); %d reference stamps passed on by both halves, largest difference %.3g rad; "
                    + "the new half's blend_duration %.3f s with blend_time %s%n", r.out().lines().filter(
                    l -> l.contains("committed")).findFirst().orElse(""), r.jump() * 1e3, ONE_CYCLE * 1e3,
                    r.before() * 1e3, same, sameDiff, duration, get.strip());
            assertEquals(0.5, duration, 0.0, "blend_duration of the converted state");
            assertTrue(same > 500, "reference stamps passed on by both halves: " + same);
            assertTrue(sameDiff < 1e-9, "the two halves differ by " + sameDiff + " rad for the same reference stamp");
            assertTrue(r.jump() <= ONE_CYCLE * 1.02, "the robot's reference stepped " + r.jump()
                    + " rad per source cycle between the versions");
            assertEquals(List.of(), CellRig.awaitingReset(rt));
            assertTrue(CellRig.armFollows(rt, "trajectory"), rt.cmd("arflex:bindings"));

            // the way back: another state type, no conversion declared: refused by the plan
            String refused = rt.cmd("arflex:change plan update tcp-correction file:" + old + " " + UpdateSetIT.sha256(old));
            System.out.println("StateConversionIT: back to 1.0.5:\n" + refused);
            assertTrue(refused.contains("state block: the running version 1.1.0 hands over arflex.TcpCorrectionState2 "
                    + "1.0, the new version 1.0.5 takes arflex.TcpCorrectionState 1.0 and declares no conversion from "
                    + "arflex.TcpCorrectionState2 1.0"), refused);
            assertTrue(Runtime.rtProcesses(rt.rid).stream().noneMatch(p -> p.contains("--instance 2-tcp-correction ")));
        }
    }
}
