package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertNotEquals;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.List;
import java.util.Locale;
import java.util.Map;
import java.util.zip.ZipEntry;
import java.util.zip.ZipFile;
import java.util.zip.ZipOutputStream;
import org.junit.jupiter.api.Test;

/**
 * Issue #19's "vision is replaced while correction runs" (docs/DECISIONS.md D40): on the moving
 * arm (FailSafeIT's looping program) with the four cameras and vision feeding tcp-correction
 * (its {@code tcp_pose} input), vision is updated to a new version in a change set, {@code
 * arflex:change apply update vision file:<jar> <sha256> window 10}: the new half runs beside
 * the old one on the same frames, tcp-correction gets one BIND of its pose input to it, and after
 * the window the old half stops. Version 1.0.1 is the built vision bundle under a new contract
 * version, pinned (made as UpdateSetIT makes tcp-correction's).
 *
 * <p>Asserted: the set is applied and committed; the guard never leaves NORMAL and sim-robot runs
 * no safe cycle; nothing waits for a reset or a fresh command; sim-robot, the guard, trajectory
 * and tcp-correction keep their pids; vision runs the new version (a new pid, 1.0.1) and its
 * poses reach tcp-correction again (its error output, written per vision measurement, goes on);
 * the robot's reference never steps more than ChangeSetIT's bound per cycle of its source.
 */
class VisionChangeSetIT {

    static final long T = CellRig.T;
    static final Path VISION = Components.jar("vision");
    static final Path CAMERAS = Components.jar("sim-camera");

    /** A copy of {@code bundle} with the version of its contract {@code name} set. */
    static Path version(Path bundle, String name, Path dir, String version) throws Exception {
        Path out = dir.resolve(name + "-" + version + ".jar");
        String contract = "OSGI-INF/arflex/" + name + ".xml";
        try (ZipFile in = new ZipFile(bundle.toFile()); ZipOutputStream zo = new ZipOutputStream(Files.newOutputStream(out))) {
            boolean found = false;
            for (ZipEntry e : java.util.Collections.list(in.entries())) {
                byte[] b = in.getInputStream(e).readAllBytes();
                if (e.getName().equals(contract)) {
                    String xml = new String(b, StandardCharsets.UTF_8);
                    String bumped = xml.replaceFirst("name=\"" + name + "\" version=\"[^\"]+\"",
                            "name=\"" + name + "\" version=\"" + version + "\"");
                    assertNotEquals(xml, bumped, "the contract's version attribute");
                    b = bumped.getBytes(StandardCharsets.UTF_8);
                    found = true;
                }
                zo.putNextEntry(new ZipEntry(e.getName()));
                zo.write(b);
                zo.closeEntry();
            }
            assertTrue(found, contract + " in " + bundle);
        }
        return out;
    }

    @Test
    void visionIsUpdatedWhileTheCorrectionRunsOnTheMovingArm() throws Exception {
        CellRig.assertBuilt(CellRig.SIM_ROBOT, CellRig.TRAJECTORY, CellRig.FORCE_GUARD, CellRig.TCP_CORRECTION, VISION,
                CAMERAS);
        try (Runtime rt = new Runtime("changeset-vision")) {
            FailSafeIT.movingCell(rt);
            rt.installAndStart(CAMERAS);
            rt.installAndStart(VISION);
            rt.awaitState("ACTIVE", T, "vision", "sim-camera-0", "sim-camera-1", "sim-camera-2", "sim-camera-3");
            rt.waitUntil("tcp-correction.tcp_pose bound to vision", T,
                    () -> rt.cmd("arflex:bindings").contains("tcp-correction.tcp_pose <- vision.tcp_pose"));
            // tcp-correction holds a measurement whose sigma exceeds max_sigma (0.2 mm by default);
            // on this moving program most of vision's are 0.1-2.3 mm (D58), so few reached it and
            // the correction was barely exercised across the update (and the wait below timed out
            // under load). 3 mm lets them through; max_rate (0.01 rad/s) still bounds the correction's
            // change to 0.01 mrad per cycle, far inside the reference-step bound asserted below.
            CellRig.set(rt, "tcp-correction", "max_sigma", "0.003");
            Path jar = version(VISION, "vision", Files.createDirectories(rt.dir.resolve("versions")), "1.0.1");
            long robotPid = rt.pid("sim-robot");
            long guardPid = rt.pid("force-guard");
            long trajPid = rt.pid("trajectory");
            long corrPid = rt.pid("tcp-correction");
            long visionPid = rt.pid("vision");
            assertTrue(Runtime.rtProcesses(rt.rid).stream().anyMatch(p -> p.contains("--instance vision ")),
                    "vision's process is seen before the update");
            CellRig.Trace<CellRig.Ref> ref = new CellRig.Trace<>();
            CellRig.Trace<CellRig.JointState> js = new CellRig.Trace<>();
            CellRig.Trace<CellRig.Safety> safety = new CellRig.Trace<>();
            CellRig.Trace<CellRig.Sample> err = new CellRig.Trace<>();
            try (CellRig.Port rp = new CellRig.Port(rt.segment("tcp-correction", "corrected"), CellRig.REF_SIZE);
                    CellRig.Port jp = new CellRig.Port(rt.segment("sim-robot", "joint_state"), CellRig.JOINT_STATE_SIZE);
                    CellRig.Port sp = new CellRig.Port(rt.segment("force-guard", "safety"), CellRig.SAFETY_SIZE);
                    CellRig.Port ep = new CellRig.Port(rt.segment("tcp-correction", "error"), CellRig.SAMPLE_SIZE);
                    CellRig.Recorder rec = new CellRig.Recorder()) {
                rec.add(rp, CellRig.Ref::of, CellRig.Ref::seq, ref::add);
                rec.add(jp, CellRig.JointState::of, CellRig.JointState::seq, js::add);
                rec.add(sp, CellRig.Safety::of, CellRig.Safety::seq, safety::add);
                rec.add(ep, CellRig.Sample::of, CellRig.Sample::seq, err::add);
                rec.start();
                // with max_sigma 3 mm (above) most measurements reach tcp-correction; the deadline stays
                // twice T for a machine whose cameras and vision are starved by other work
                rt.waitUntil("the arm moving and vision's measurements reaching tcp-correction (3 seen)", 2 * T,
                        () -> FailSafeIT.moving(js) && err.size() > 3);
                assertTrue(CellRig.awaitingReset(rt).isEmpty(), "before: " + CellRig.awaitingReset(rt));
                Map<String, Object> robot0 = ChangeSetIT.stats(rt, "sim-robot");
                int mark = ref.size();
                int logMark = rt.logMark();
                long t0 = System.nanoTime();
                String out = rt.cmd("arflex:change apply update vision file:" + jar + " " + UpdateSetIT.sha256(jar)
                        + " window 10");
                System.out.printf(Locale.ROOT, "VisionChangeSetIT: apply (%.0f ms):%n%s%n", (System.nanoTime() - t0) / 1e6, out);
                assertTrue(out.contains("\napplied: ") && out.contains("update vision: committed"), out);
                int errAfter = err.size();
                rt.waitUntil("vision's measurements reaching tcp-correction after the update (3 more)", T,
                        () -> err.size() > errAfter + 3);
                int after = ref.size();
                rt.waitUntil("2000 references after the update", T, () -> ref.size() > after + 2000);
                assertNull(rec.error, () -> "recorder: " + rec.error);
                List<CellRig.Ref> rs = ref.snapshot();
                double before = ReconfigBench.steps(rs.subList(0, mark));
                double jump = ReconfigBench.steps(rs.subList(Math.max(0, mark - 1), rs.size()));
                List<CellRig.Safety> ss = safety.snapshot();
                double force = ss.stream().mapToDouble(CellRig.Safety::forceNorm).max().orElseThrow();
                Map<String, Object> robot1 = ChangeSetIT.stats(rt, "sim-robot");
                System.out.printf(Locale.ROOT, "VisionChangeSetIT: largest step of the robot's reference from the apply "
                        + "on %.3f mrad per source cycle (bound %.3f; before %.3f); largest force %.1f N; sim-robot %d "
                        + "cycles, %d overruns, %d safe cycles; vision measurements seen by tcp-correction %d before, %d "
                        + "after the command returned%n", jump * 1e3, ChangeSetIT.JUMP_BOUND * 1e3, before * 1e3, force,
                        ChangeSetIT.delta(robot0, robot1, "cycles"), ChangeSetIT.delta(robot0, robot1, "overruns"),
                        ChangeSetIT.delta(robot0, robot1, "safeCycles"), errAfter, err.size() - errAfter);
                assertTrue(jump <= ChangeSetIT.JUMP_BOUND, "reference step " + jump + " rad per source cycle");
                assertNull(ss.stream().filter(s -> s.mode() != CellRig.Safety.NORMAL).findFirst().orElse(null),
                        "the guard left NORMAL");
                assertEquals(0, ChangeSetIT.delta(robot0, robot1, "safeCycles"), "sim-robot ran safe cycles");
                SwitchWindow.of(rt.logSince(logMark)).assertNoReleaseLost("VisionChangeSetIT", js.snapshot());
            }
            assertEquals(List.of(), CellRig.awaitingReset(rt));
            assertEquals(List.of(), CellRig.awaitingCommand(rt));
            rt.awaitState("ACTIVE", T, "vision", "trajectory", "tcp-correction", "sim-robot", "force-guard");
            assertEquals(robotPid, rt.pid("sim-robot"));
            assertEquals(guardPid, rt.pid("force-guard"));
            assertEquals(trajPid, rt.pid("trajectory"));
            assertEquals(corrPid, rt.pid("tcp-correction"));
            assertNotEquals(visionPid, rt.pid("vision"), "the new version runs");
            assertTrue(rt.cmd("arflex:info vision").contains("1.0.1"), rt.cmd("arflex:info vision"));
            rt.waitUntil("the old version's process and segment gone", T, () -> Runtime.rtProcesses(rt.rid).stream()
                    .noneMatch(p -> p.contains("--instance vision ")) && !Files.exists(rt.segment("vision", "tcp_pose")));
        }
    }
}
