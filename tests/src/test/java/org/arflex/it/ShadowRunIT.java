package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertNotEquals;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Locale;
import java.util.Map;
import java.util.function.UnaryOperator;
import java.util.regex.Matcher;
import java.util.regex.Pattern;
import org.junit.jupiter.api.Test;

/**
 * docs/DECISIONS.md D42 through the real runtime, on the moving arm of UpdateSetIT (FailSafeIT's
 * looping program; trajectory -> tcp-correction -> sim-robot): an update's new version first runs
 * in shadow, on the running version's inputs with its outputs read by nobody but the runtime,
 * and is compared with the running version before anything is switched. Versions are made here
 * from the built bundles and pinned, as in UpdateSetIT:
 * <ul>
 * <li>tcp-correction 1.0.2-faulty (a script that runs the real executable with rt-core's test
 * fault of a SIGSEGV in its 50th update after its START, D68; a crash 150 ms after its spawn
 * fell before its START on a loaded machine): rejected in shadow (200 cycles);
 * sim-robot never rebound, no safe cycle, the guard NORMAL, no reset, every pid unchanged;</li>
 * <li>sample-scaler 1.0.1-gain (its contract's gain 2.5 where the running version's is 2.0, in
 * the same runtime beside the moving arm): its output differs from the running version's by
 * more than the tolerance the command gives, rejected naming the field and both values;</li>
 * <li>tcp-correction 1.0.1 whose contract declares {@code <rollout shadow="200" window="500">}
 * and a tolerance on {@code corrected.q}: passes its shadow run, is switched and committed.</li>
 * </ul>
 */
class ShadowRunIT {

    static final long T = CellRig.T;
    static final Path SAMPLE_COUNTER = Components.jar("sample-counter");
    static final Path SAMPLE_SCALER = Components.jar("sample-scaler");

    /**
     * A copy of {@code bundle} whose contract {@code contractEntry} is rewritten by {@code contract}
     * (which must change it), and whose entry {@code exeEntry} is replaced by {@code exe} when given.
     */
    static Path version(Path dir, Path bundle, String name, String contractEntry, UnaryOperator<String> contract,
                        String exeEntry, byte[] exe) throws IOException {
        Map<String, UnaryOperator<byte[]>> edits = new LinkedHashMap<>();
        edits.put(contractEntry, BundleCopies.text(contract, "the contract of " + name));
        if (exe != null) {
            edits.put(exeEntry, b -> exe);
        }
        return BundleCopies.copy(dir, bundle, name, edits);
    }

    static UnaryOperator<String> versioned(String component, String version) {
        return xml -> xml.replaceFirst("name=\"" + component + "\" version=\"[^\"]+\"",
                "name=\"" + component + "\" version=\"" + version + "\"");
    }

    /** Every instance's pid by name (0: none). */
    static Map<String, Long> pids(Runtime rt) {
        Map<String, Long> out = new LinkedHashMap<>();
        for (Map<String, Object> i : Runtime.list(rt.dto(), "instances")) {
            Object pid = i.get("pid");
            out.put((String) i.get("name"), pid == null ? 0 : ((Number) pid).longValue());
        }
        return out;
    }

    /**
     * Applies {@code update <component> <jar> <pin> <options>} on the moving arm and checks that it
     * is rejected in shadow with nothing of the cell changed; returns the command's output.
     */
    static String rejected(Runtime rt, String component, Path jar, String options) throws Exception {
        CellRig.Trace<CellRig.JointState> js = new CellRig.Trace<>();
        CellRig.Trace<CellRig.Safety> safety = new CellRig.Trace<>();
        try (CellRig.Port jp = new CellRig.Port(rt.segment("sim-robot", "joint_state"), CellRig.JOINT_STATE_SIZE);
                CellRig.Port sp = new CellRig.Port(rt.segment("force-guard", "safety"), CellRig.SAFETY_SIZE);
                CellRig.Recorder rec = new CellRig.Recorder()) {
            rec.add(jp, CellRig.JointState::of, CellRig.JointState::seq, js::add);
            rec.add(sp, CellRig.Safety::of, CellRig.Safety::seq, safety::add);
            rec.start();
            rt.waitUntil("the arm moving", T, () -> FailSafeIT.moving(js));
            assertTrue(CellRig.awaitingReset(rt).isEmpty(), "before: " + CellRig.awaitingReset(rt));
            Map<String, Long> before = pids(rt);
            String bindings = rt.cmd("arflex:bindings");
            Map<String, Object> robot0 = ChangeSetIT.stats(rt, "sim-robot");
            int restarts = ((Number) rt.instance(component).get("restarts")).intValue();
            String version = rt.cmd("arflex:info " + component).lines().findFirst().orElse("");
            int logMark = rt.logMark();
            long t0 = System.nanoTime();
            String out = rt.cmd("arflex:change apply update " + component + " file:" + jar + " " + UpdateSetIT.sha256(jar)
                    + " " + options);
            long tookMs = (System.nanoTime() - t0) / 1_000_000;
            System.out.println("ShadowRunIT: apply (" + tookMs + " ms):\n" + out);
            List<String> log = rt.logSince(logMark);
            System.out.println("ShadowRunIT: the runtime's log of the update:\n" + String.join("\n", log.stream()
                    .filter(l -> l.contains(component) && !l.contains("  ")).toList()));
            assertTrue(out.contains("\nrefused: update " + component + ": rejected in shadow after "), out);
            // the consumers were never rebound: no rewiring, the same bindings
            assertTrue(log.stream().noneMatch(l -> l.contains(" rewired by ")), String.join("\n", log));
            assertEquals(bindings, rt.cmd("arflex:bindings"));
            rt.waitUntil("the rejected version's process and segments gone", T, () -> Runtime.rtProcesses(rt.rid).stream()
                    .noneMatch(p -> p.contains("--instance 1-" + component + " ")) && Files.list(Path.of("/dev/shm"))
                    .noneMatch(f -> f.getFileName().toString().startsWith("arflex." + rt.rid + ".1-" + component + ".")));
            // a while on the arm after it
            int n = js.size();
            rt.waitUntil("1000 more robot states", T, () -> js.size() > n + 1000);
            assertNull(rec.error, () -> "recorder: " + rec.error);
            Map<String, Object> robot1 = ChangeSetIT.stats(rt, "sim-robot");
            CellRig.Safety tripped = safety.snapshot().stream().filter(s -> s.mode() != CellRig.Safety.NORMAL).findFirst()
                    .orElse(null);
            double force = safety.snapshot().stream().mapToDouble(CellRig.Safety::forceNorm).max().orElse(0);
            long safeCycles = ChangeSetIT.delta(robot0, robot1, "safeCycles");
            System.out.printf(Locale.ROOT, "ShadowRunIT: %s rejected after %d ms; sim-robot over %d cycles from the apply: "
                    + "%d safe cycles, %d overruns; largest force the guard read %.1f N%n", component, tookMs,
                    ChangeSetIT.delta(robot0, robot1, "cycles"), safeCycles, ChangeSetIT.delta(robot0, robot1, "overruns"),
                    force);
            assertNull(tripped, "the guard left NORMAL: " + tripped);
            assertEquals(0, safeCycles, "sim-robot ran safe cycles");
            assertEquals(List.of(), CellRig.awaitingReset(rt));
            assertEquals(List.of(), CellRig.awaitingCommand(rt));
            assertEquals(before, pids(rt), "every half runs on with its pid");
            assertEquals(restarts, ((Number) rt.instance(component).get("restarts")).intValue(), "no restart");
            assertEquals(version, rt.cmd("arflex:info " + component).lines().findFirst().orElse(""),
                    "the running version is the component's");
            return out;
        }
    }

    @Test
    void aVersionThatCrashesInShadowIsRejectedWithNothingSwitched() throws Exception {
        CellRig.assertBuilt(CellRig.SIM_ROBOT, CellRig.TRAJECTORY, CellRig.FORCE_GUARD, CellRig.TCP_CORRECTION);
        try (Runtime rt = new Runtime("shadow-crash")) {
            FailSafeIT.movingCell(rt);
            Path dir = Files.createDirectories(rt.dir.resolve("versions"));
            byte[] script = FaultyVersions.crashingAfterCycles(dir, CellRig.TCP_CORRECTION, UpdateSetIT.EXE, 50, "ShadowRunIT");
            Path jar = version(dir, CellRig.TCP_CORRECTION, "tcp-correction-1.0.2-faulty", UpdateSetIT.CONTRACT,
                    versioned("tcp-correction", "1.0.2-faulty"), UpdateSetIT.EXE, script);
            long oldPid = rt.pid("tcp-correction");
            String out = rejected(rt, "tcp-correction", jar, "shadow 200 tolerance corrected.q 0.000001");
            Matcher m = Pattern.compile("rejected in shadow after (\\d+) cycles: the new version \\(pid \\d+\\) exited: "
                    + "killed by signal 11").matcher(out);
            assertTrue(m.find(), out);
            long cycles = Long.parseLong(m.group(1));
            assertTrue(cycles < 200, "crashed within its shadow run: " + cycles);
            assertTrue(out.contains("nothing changed (pid " + oldPid + " runs tcp-correction on)"), out);
            assertTrue(CellRig.armFollows(rt, "trajectory"), rt.cmd("arflex:bindings"));
            System.out.printf(Locale.ROOT, "ShadowRunIT: the faulty version ran %d shadow cycles%n", cycles);
        }
    }

    @Test
    void aVersionWhoseOutputDivergesIsRejectedInShadowNamingTheField() throws Exception {
        CellRig.assertBuilt(CellRig.SIM_ROBOT, CellRig.TRAJECTORY, CellRig.FORCE_GUARD, SAMPLE_COUNTER, SAMPLE_SCALER);
        try (Runtime rt = new Runtime("shadow-diverge")) {
            FailSafeIT.movingCell(rt);
            rt.installAndStart(SAMPLE_COUNTER);
            rt.installAndStart(SAMPLE_SCALER);
            rt.awaitState("ACTIVE", T, "sample-counter", "sample-scaler");
            Path dir = Files.createDirectories(rt.dir.resolve("versions"));
            // the same executable; the new contract's gain is 2.5 (the running version's 2.0 lies
            // outside its new range, so it is not carried over)
            Path jar = version(dir, SAMPLE_SCALER, "sample-scaler-1.0.1-gain", "OSGI-INF/arflex/sample-scaler.xml",
                    xml -> versioned("sample-scaler", "1.0.1-gain").apply(xml).replace(
                            "default=\"2.0\" min=\"-10\" max=\"10\"", "default=\"2.5\" min=\"2.1\" max=\"10\""),
                    null, null);
            String out = rejected(rt, "sample-scaler", jar, "shadow 100 tolerance y.value 0.001");
            Matcher m = Pattern.compile("rejected in shadow after (\\d+) cycles: output y.value = (\\S+) differs from "
                    + "the running version's (\\S+) by (\\S+) \\(the same source cycle, t_ns \\d+\\), beyond its tolerance "
                    + "0.001").matcher(out);
            assertTrue(m.find(), out);
            double mine = Double.parseDouble(m.group(2));
            double theirs = Double.parseDouble(m.group(3));
            assertEquals(2.5 / 2.0, mine / theirs, 1e-9, "the values of one source cycle, gain 2.5 against 2.0");
            System.out.printf(Locale.ROOT, "ShadowRunIT: the diverging version was rejected after %s cycles: %s against %s%n",
                    m.group(1), m.group(2), m.group(3));
        }
    }

    @Test
    void aGoodVersionPassesItsContractDeclaredShadowRunAndIsCommitted() throws Exception {
        CellRig.assertBuilt(CellRig.SIM_ROBOT, CellRig.TRAJECTORY, CellRig.FORCE_GUARD, CellRig.TCP_CORRECTION);
        try (Runtime rt = new Runtime("shadow-pass")) {
            FailSafeIT.movingCell(rt);
            Path dir = Files.createDirectories(rt.dir.resolve("versions"));
            Path jar = version(dir, CellRig.TCP_CORRECTION, "tcp-correction-1.0.1", UpdateSetIT.CONTRACT,
                    xml -> versioned("tcp-correction", "1.0.1").apply(xml).replace("</component>",
                            "  <rollout shadow=\"200\" window=\"500\">\n"
                                    + "    <tolerance port=\"corrected\" field=\"q\" abs=\"0.000001\"/>\n"
                                    + "  </rollout>\n</component>"), null, null);
            UpdateSetIT.Run r = UpdateSetIT.update(rt, jar, "");
            Matcher m = Pattern.compile("update tcp-correction: passed its shadow run of (\\d+) cycles \\((\\d+) cycles late, "
                    + "the running version (\\d+)[^;]*; (\\d+) values compared, corrected.q at most (\\S+) "
                    + "from the running version's").matcher(r.out());
            assertTrue(m.find(), r.out());
            assertTrue(Long.parseLong(m.group(1)) >= 200, r.out());
            assertTrue(Long.parseLong(m.group(4)) > 0, r.out());
            assertTrue(r.out().contains("update tcp-correction: committed: the new version ran"), r.out());
            assertTrue(r.jump() <= ChangeSetIT.JUMP_BOUND, "reference step " + r.jump() + " rad per source cycle");
            rt.awaitState("ACTIVE", T, "tcp-correction", "sim-robot", "force-guard", "trajectory");
            assertNotEquals(r.oldPid(), rt.pid("tcp-correction"), "the new version runs");
            assertEquals(0, ((Number) rt.instance("tcp-correction").get("restarts")).intValue());
            assertTrue(rt.cmd("arflex:info tcp-correction").contains("1.0.1"), rt.cmd("arflex:info tcp-correction"));
            rt.waitUntil("the old version's process and segment gone", T, () -> Runtime.rtProcesses(rt.rid).stream()
                    .noneMatch(p -> p.contains("--instance tcp-correction ")) && !Files.exists(
                    rt.segment("tcp-correction", "corrected")));
            System.out.printf(Locale.ROOT, "ShadowRunIT: passed: %d shadow cycles, %s/%s overruns, %s values compared, "
                    + "largest difference %s rad; command %d ms%n", Long.parseLong(m.group(1)), m.group(2), m.group(3),
                    m.group(4), m.group(5), r.applyMs());
        }
    }
}
