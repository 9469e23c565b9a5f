package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertNotNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.Collections;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import java.util.Random;
import java.util.Set;
import java.util.TreeSet;
import java.util.concurrent.atomic.AtomicReference;
import org.junit.jupiter.api.AfterAll;
import org.junit.jupiter.api.BeforeAll;
import org.junit.jupiter.api.MethodOrderer;
import org.junit.jupiter.api.Order;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.TestInstance;
import org.junit.jupiter.api.TestMethodOrder;

/**
 * The main job's cell end to end through the real runtime: the runtime assembly with
 * {@code arflex.evaluation=true} (sim-robot publishes the simulator's ground truth, read here
 * only), the bundles and settings of its own {@code conf/cell.gosh} installed in a shuffled
 * (seeded) order, real RT processes, real cameras rendering 1280x1024 frames, vision, and the
 * tcp-correction outer loop. The steps share one runtime and run in order:
 * <ol>
 * <li>every component of the cell reaches ACTIVE, wired as the contracts say (filters);</li>
 * <li>the robot follows the demonstration program (its joints swing through the program's
 * targets and settle at its last target, tracking the corrected reference);</li>
 * <li>the TRUE static TCP error with the correction on is far below the error with it off
 * (ratio asserted with margin; figures printed);</li>
 * <li>vision loss at runtime: the cameras are uninstalled and reinstalled; tcp-correction,
 * sim-robot, trajectory and vision keep their processes and keep cycling, the robot's
 * reference never steps beyond the correction's rate limit, and the loop comes back;</li>
 * <li>a debug monitor installed while the cell runs reads tcp-correction's internal values and
 * is uninstalled; the rest keeps cycling.</li>
 * </ol>
 * Waits are conditions with deadlines; nothing is asserted on timing. The runtime's leak check
 * ({@link Runtime#close()}) runs at the end.
 */
@TestInstance(TestInstance.Lifecycle.PER_CLASS)
@TestMethodOrder(MethodOrderer.OrderAnnotation.class)
class CellE2EIT {

    /** Components conf/cell.gosh installs (the cell of the main job). */
    static final Set<String> CELL = Set.of("force-guard", "trajectory", "tool-gripper", "sim-robot", "tcp-correction",
            "sim-camera-0", "sim-camera-1", "sim-camera-2", "sim-camera-3", "vision", "sample-counter", "sample-scaler");
    /** The components whose cycling is watched across structural changes. */
    static final String[] LOOP = {"sim-robot", "trajectory", "tcp-correction", "force-guard", "vision"};
    /** Last target of the built-in demonstration program (bundles/trajectory/native/trajectory.cc). */
    static final double[] FINAL = {0, 0.2, 0.5, 0, 0.6, 0};
    /** tcp-correction's max_rate (contract default), rad/s, and the servo period, s. */
    static final double MAX_RATE = 0.01;
    static final double PERIOD = 0.001;
    static final long T = 60_000;

    Runtime rt;
    Path evalAssembly;
    final Map<String, Long> bundleIds = new LinkedHashMap<>();
    final Map<String, Path> jars = new LinkedHashMap<>();
    final List<String> report = new ArrayList<>();
    final Map<String, Long> pids = new LinkedHashMap<>();
    final Map<String, Long> cycles = new LinkedHashMap<>();
    final Map<String, Long> updateErrors = new LinkedHashMap<>();
    double errOffMm = Double.NaN;
    double errOnMm = Double.NaN;

    @BeforeAll
    void startRuntime() throws Exception {
        // A private copy of the assembly whose configuration makes this an evaluation run.
        evalAssembly = Path.of(System.getProperty("arflex.it.work")).resolve("cell-e2e-assembly");
        rt = CellRig.evaluationRuntime("cell-e2e", evalAssembly);
        operator = new CellRig.Operator(rt);
        report.add(rt.renice(-10));
    }

    @AfterAll
    void stopRuntime() throws Exception {
        report.add("operator resets (only trips the test caused; any other fails it, D77): "
                + (operator == null ? "{}" : operator.resets));
        if (operator != null) {
            operator.close();
        }
        System.out.println("CellE2EIT report:");
        report.forEach(r -> System.out.println("  " + r));
        try {
            if (rt != null) {
                rt.close();
            }
        } finally {
            Runtime.deleteTree(evalAssembly);
        }
    }

    // ---- helpers --------------------------------------------------------------------------

    Path seg(String inst, String port) {
        return rt.segment(inst, port);
    }

    @SuppressWarnings("unchecked")
    static long cyclesOf(Map<String, Object> inst) {
        Map<String, Object> st = (Map<String, Object>) inst.get("stats");
        return st == null ? -1 : ((Number) st.get("cycles")).longValue();
    }

    CellRig.Operator operator;

    /**
     * The operator at the cell (CellRig.Operator): at most once a second, resets the guard's trip
     * the test caused (the push), and fails the test on any other component waiting for a reset,
     * naming its cause (a trip's force and sim-robot's release gaps before it, D77).
     */
    void operator() {
        operator.tick();
    }

    /** Records pids and cycle counters of the loop's components as the reference point. */
    void markLoop(String step) {
        Map<String, Object> dto = rt.dto();
        for (String n : LOOP) {
            Map<String, Object> i = Runtime.list(dto, "instances").stream().filter(x -> n.equals(x.get("name")))
                    .findFirst().orElseThrow();
            pids.put(n, ((Number) i.get("pid")).longValue());
            cycles.put(n, cyclesOf(i));
            updateErrors.put(n, statOf(i, "updateErrors"));
        }
        report.add(step + ": pids " + pids + ", cycles " + cycles + ", update errors " + updateErrors);
    }

    static long statOf(Map<String, Object> inst, String key) {
        @SuppressWarnings("unchecked")
        Map<String, Object> st = (Map<String, Object>) inst.get("stats");
        return st == null ? -1 : ((Number) st.get(key)).longValue();
    }

    /**
     * Same pids as at the mark, ACTIVE, cycle counters past the mark, and no update error since
     * the mark (a torn or missing input a component needs, or a refused reference, counts one).
     */
    void assertLoopKeptCycling(String step) {
        for (String n : LOOP) {
            long before = cycles.get(n);
            long[] now = {0};
            rt.waitUntil(n + " cycling past " + before + " with pid " + pids.get(n) + " at '" + step + "'", T, () -> {
                Map<String, Object> i = rt.instance(n);
                assertEquals("ACTIVE", i.get("state"), n + " at '" + step + "'");
                assertEquals(pids.get(n), ((Number) i.get("pid")).longValue(), n + " was restarted at '" + step + "'");
                now[0] = cyclesOf(i);
                if (now[0] > before) {
                    assertEquals(updateErrors.get(n), statOf(i, "updateErrors"), n + " had update errors at '" + step + "'");
                }
                return now[0] > before;
            });
            cycles.put(n, now[0]);
        }
        report.add(step + ": same pids, cycles " + cycles);
    }

    /**
     * Polls the motion chain's ports every 2 ms on its own thread: the program's reference, the
     * corrected reference, the joint state. Keeps the joint 1 range seen and, while armed, the
     * largest step of the corrected reference beyond the correction's rate limit (per cycle of
     * tcp-correction, counted by the output's seq) and whether the program's reference moved.
     */
    final class Recorder implements AutoCloseable {
        final AtomicReference<String> error = new AtomicReference<>();
        volatile double q1Min = Double.MAX_VALUE;
        volatile double q1Max = -Double.MAX_VALUE;
        volatile boolean armed;
        volatile double maxExcess;
        volatile double maxRefMove;
        volatile long samples;
        volatile CellPorts.Joints lastCorrected;
        private CellPorts.Joints armedRef;
        private final CellPorts.State ref;
        private final CellPorts.State corrected;
        private final CellPorts.State state;
        private final Thread thread;
        private volatile boolean stop;

        Recorder() throws IOException {
            ref = new CellPorts.State(seg("trajectory", "joint_ref"), CellPorts.JOINT_REF);
            corrected = new CellPorts.State(seg("tcp-correction", "corrected"), CellPorts.JOINT_REF);
            state = new CellPorts.State(seg("sim-robot", "joint_state"), CellPorts.JOINT_STATE);
            thread = new Thread(this::run, "cell-e2e-recorder");
            thread.setDaemon(true);
            thread.start();
        }

        void arm() {
            maxExcess = 0;
            maxRefMove = 0;
            armedRef = null;
            armed = true;
        }

        private void run() {
            CellPorts.Joints last = null;
            while (!stop) {
                CellPorts.Joints s = CellPorts.Joints.of(state.read(), true);
                if (s != null) {
                    q1Min = Math.min(q1Min, s.q()[0]);
                    q1Max = Math.max(q1Max, s.q()[0]);
                }
                CellPorts.Joints c = CellPorts.Joints.of(corrected.read(), false);
                CellPorts.Joints r = CellPorts.Joints.of(ref.read(), false);
                if (c != null) {
                    if (last != null && c.seq() < last.seq() && error.get() == null) {
                        error.set("tcp-correction's output seq went back from " + last.seq() + " to " + c.seq());
                    }
                    if (armed && last != null && c.seq() > last.seq()) {
                        double limit = MAX_RATE * PERIOD * (c.seq() - last.seq());
                        maxExcess = Math.max(maxExcess, c.maxAbsDiff(last) - limit);
                    }
                    last = c;
                    lastCorrected = c;
                    samples++;
                }
                if (armed && r != null) {
                    if (armedRef == null) {
                        armedRef = r;
                    }
                    maxRefMove = Math.max(maxRefMove, r.maxAbsDiff(armedRef));
                }
                try {
                    Thread.sleep(2); // sampling interval of a recorder, not a wait for a condition
                } catch (InterruptedException e) {
                    return;
                }
            }
        }

        @Override
        public void close() throws Exception {
            stop = true;
            thread.interrupt();
            thread.join(10_000);
            ref.close();
            corrected.close();
            state.close();
        }
    }

    /** The TRUE TCP error now (mm): the simulator's true TCP against the program's target. */
    static double trueErrorMm(CellPorts.State truth, CellPorts.State ref) {
        return CellRig.trueErrorMm(truth, ref);
    }

    /**
     * Waits until the true error has settled: {@code n} consecutive new vision measurements
     * (tcp-correction's error output) with the robot at rest, the true error after each within
     * {@code bandMm} of the one before. Returns the mean of those true errors (mm).
     */
    double settledTrueError(String what, int n, double bandMm, long timeoutMs) throws IOException {
        try (CellRig.AccuracyPorts p = CellRig.AccuracyPorts.open(rt)) {
            List<double[]> all = CellRig.settle(rt, operator, p, n, bandMm, System.nanoTime(), timeoutMs);
            StringBuilder trace = new StringBuilder();
            for (double[] x : all) {
                if (trace.length() < 2000) {
                    trace.append(String.format(" %.4f", x[1]));
                }
            }
            report.add(what + ": true error after each measurement (mm):" + trace);
            return CellRig.meanOfLast(all, n);
        }
    }

    // ---- the steps ------------------------------------------------------------------------

    @Test
    @Order(1)
    void cellInstalledInAShuffledOrderAllActiveAndWired() throws Exception {
        CellRig.Gosh gosh = CellRig.cellGosh(rt);
        List<Path> toStart = new ArrayList<>(gosh.starts());
        List<String> settings = gosh.settings();
        long seed = Long.getLong("arflex.it.seed", System.nanoTime());
        Collections.shuffle(toStart, new Random(seed));
        report.add("install order (seed " + seed + ", rerun with -Darflex.it.seed=" + seed + "): "
                + toStart.stream().map(p -> p.getFileName().toString()).toList());
        for (Path jar : toStart) {
            assertTrue(Files.isRegularFile(jar), "cell bundle missing: " + jar);
            jars.put(jar.getFileName().toString(), jar);
            bundleIds.put(jar.getFileName().toString(), rt.installAndStart(jar));
        }
        rt.awaitState("ACTIVE", 120_000, CELL.toArray(new String[0]));
        // Settings go to the running components (as scripts/run-cell.sh does): a value set
        // before a bundle's start has been processed is replaced by the contract's defaults.
        for (String s : settings) {
            String[] w = s.split("\\s+");
            String r = rt.cmd(s);
            assertTrue(r.startsWith(w[1] + "." + w[2] + " = "), s + ": " + r);
            assertEquals(Double.parseDouble(w[3]), Double.parseDouble(rt.cmd("arflex:get " + w[1] + " " + w[2])), 0.0, s);
        }
        Map<String, Object> dto = rt.dto();
        assertEquals(new TreeSet<>(CELL), new TreeSet<>(Runtime.names(dto, i -> true)), "the cell's instances");
        String bindings = rt.cmd("arflex:bindings");
        for (String b : List.of("tcp-correction.reference <- trajectory.joint_ref",
                "sim-robot.joint_ref <- tcp-correction.corrected", "tcp-correction.tcp_pose <- vision.tcp_pose",
                "vision.cam0 <- sim-camera-0.frames", "vision.cam3 <- sim-camera-3.frames",
                "trajectory.safety <- force-guard.safety", "tool-gripper.safety <- force-guard.safety")) {
            assertTrue(bindings.contains(b), "binding '" + b + "' missing:\n" + bindings);
        }
        @SuppressWarnings("unchecked")
        Map<String, Object> eval = (Map<String, Object>) rt.instance("sim-robot").get("evaluationSegments");
        assertTrue(eval != null && eval.containsKey("truth"), "no ground truth segment: " + eval);
        report.add("admitted: " + rt.cmd("arflex:resources").replace('\n', ';'));
        // The operator's start-up check: nothing waits for a reset once the cell is up (a
        // component that does fails here with its cause, D77).
        report.add("awaiting a reset after start-up: " + CellRig.awaitingReset(rt));
        operator.tickNow();
    }

    @Test
    @Order(2)
    void robotFollowsTheProgram() throws Exception {
        try (Recorder rec = new Recorder()) {
            // Replay the demonstration program (it ran once while the cell came up, maybe before
            // the robot was wired): loop it until the joints have swung through its targets.
            // A trip of the guard first (a 400 N push on the tool): the operator resets it and gives
            // the fresh command; with vision in the loop the arm must then follow the program again
            // (after a stop the robot takes only a reference at rest that meets it, and the
            // corrected reference is never bit-identical while vision runs).
            CellRig.set(rt, "sim-robot", "push_duration_ms", "200");
            operator.expectTrip("a 400 N push on the tool");
            CellRig.set(rt, "sim-robot", "push_force_n", "400");
            rt.waitUntil("the guard tripped by the push", 30_000, () -> CellRig.awaitingReset(rt).contains("force-guard"));
            CellRig.set(rt, "sim-robot", "push_force_n", "0");
            assertEquals("trajectory.loop = true", rt.cmd("arflex:set trajectory loop true"));
            rt.waitUntil("joint 1 of the robot swinging through the program's lin targets (y = +-0.3 m)", 120_000,
                    () -> {
                        operator();
                        return rec.q1Max > 0.1 && rec.q1Min < -0.1;
                    });
            assertEquals("trajectory.loop = false", rt.cmd("arflex:set trajectory loop false"));
            try (CellPorts.State ref = new CellPorts.State(seg("trajectory", "joint_ref"), CellPorts.JOINT_REF);
                    CellPorts.State js = new CellPorts.State(seg("sim-robot", "joint_state"), CellPorts.JOINT_STATE)) {
                double[] dev = {0, 0};
                rt.waitUntil("the program's last target reached and the robot at rest on the corrected reference", 120_000,
                        () -> {
                            operator();
                            CellPorts.Joints r = CellPorts.Joints.of(ref.read(), false);
                            CellPorts.Joints s = CellPorts.Joints.of(js.read(), true);
                            CellPorts.Joints c = rec.lastCorrected;
                            if (r == null || s == null || c == null) {
                                return false;
                            }
                            dev[0] = r.maxAbsDiff(new CellPorts.Joints(0, 0, FINAL, null));
                            dev[1] = s.maxAbsDiff(c);
                            return dev[0] < 1e-6 && s.maxAbsVelocity() < 1e-3 && dev[1] < 1e-3;
                        });
                report.add(String.format("program: joint 1 range %.3f .. %.3f rad; at the last target the arm is %.2e rad"
                        + " from the corrected reference", rec.q1Min, rec.q1Max, dev[1]));
            }
            assertEquals(null, rec.error.get());
        }
    }

    @Test
    @Order(3)
    void trueErrorWithTheCorrectionIsFarBelowWithout() throws Exception {
        try (Recorder rec = new Recorder()) {
            // Off: the correction ramps out to exactly the program's reference.
            assertEquals("tcp-correction.enable = false", rt.cmd("arflex:set tcp-correction enable false"));
            try (CellPorts.State ref = new CellPorts.State(seg("trajectory", "joint_ref"), CellPorts.JOINT_REF)) {
                rt.waitUntil("the correction ramped out", T, () -> {
                    CellPorts.Joints r = CellPorts.Joints.of(ref.read(), false);
                    CellPorts.Joints c = rec.lastCorrected;
                    return r != null && c != null && c.maxAbsDiff(r) == 0.0;
                });
            }
            errOffMm = settledTrueError("correction off", 3, 0.002, 90_000);
            // On: vision measures, tcp-correction corrects.
            assertEquals("tcp-correction.enable = true", rt.cmd("arflex:set tcp-correction enable true"));
            double[] best = {Double.MAX_VALUE};
            try (CellPorts.State truth = new CellPorts.State(seg("sim-robot", "truth"), CellPorts.TRUTH);
                    CellPorts.State ref = new CellPorts.State(seg("trajectory", "joint_ref"), CellPorts.JOINT_REF)) {
                rt.waitUntil("the true error corrected below a fifth of " + errOffMm + " mm", 120_000, () -> {
                    operator();
                    double e = trueErrorMm(truth, ref);
                    best[0] = Math.min(best[0], e);
                    return e < errOffMm / 5;
                });
            }
            errOnMm = settledTrueError("correction on", 4, 0.05, 120_000);
            double ratio = errOffMm / errOnMm;
            report.add(String.format("TRUE static TCP error at the program's last target: off %.4f mm, on %.4f mm,"
                    + " ratio %.1fx", errOffMm, errOnMm, ratio));
            assertTrue(ratio >= 5, String.format("correction on %.4f mm vs off %.4f mm: ratio %.2f < 5", errOnMm, errOffMm,
                    ratio));
            assertEquals(null, rec.error.get());
        }
    }

    @Test
    @Order(4)
    void visionLossAtRuntimeKeepsTheLoopCyclingAndTheReferenceSmooth() throws Exception {
        String cameras = "org.arflex.sim.camera.jar";
        assertNotNull(bundleIds.get(cameras), "cameras not installed by step 1");
        try (Recorder rec = new Recorder();
                CellPorts.State err = new CellPorts.State(seg("tcp-correction", "error"), CellPorts.SAMPLE)) {
            rt.waitUntil("the recorder running", T, () -> rec.samples > 10);
            markLoop("before vision loss");
            rec.arm();
            assertEquals("", rt.cmd("uninstall " + bundleIds.remove(cameras)));
            rt.waitUntil("the cameras gone", T, () -> {
                Map<String, Object> dto = rt.dto();
                return Runtime.names(dto, i -> ((String) i.get("name")).startsWith("sim-camera")
                        && !"DESTROYED".equals(i.get("state"))).isEmpty();
            });
            String bindings = rt.cmd("arflex:bindings");
            assertTrue(!bindings.contains("vision.cam"), "vision still bound to a camera:\n" + bindings);
            assertLoopKeptCycling("cameras uninstalled");
            // No new measurement can arrive now; the loop holds while the robot keeps cycling.
            CellPorts.Sample held = CellPorts.Sample.of(err.read());
            long robotAt = cycles.get("sim-robot");
            rt.waitUntil("sim-robot 2000 cycles further without cameras", T,
                    () -> cyclesOf(rt.instance("sim-robot")) > robotAt + 2000);
            CellPorts.Sample still = CellPorts.Sample.of(err.read());
            assertTrue(held != null && still != null && still.seq() <= held.seq() + 1,
                    "measurements arrived without cameras: " + held + " -> " + still);
            assertLoopKeptCycling("vision lost, 2000 robot cycles later");

            // The cameras come back: vision rebinds, measurements resume.
            jars.put(cameras, jars.get(cameras));
            bundleIds.put(cameras, rt.installAndStart(jars.get(cameras)));
            rt.awaitState("ACTIVE", 120_000, "sim-camera-0", "sim-camera-1", "sim-camera-2", "sim-camera-3");
            rt.waitUntil("vision rebound to the four cameras", T, () -> {
                String b = rt.cmd("arflex:bindings");
                return b.contains("vision.cam0 <- sim-camera-0.frames") && b.contains("vision.cam3 <- sim-camera-3.frames");
            });
            long seqBack = still.seq();
            rt.waitUntil("vision measurements arriving again", 120_000, () -> {
                CellPorts.Sample s = CellPorts.Sample.of(err.read());
                return s != null && s.seq() > seqBack + 2;
            });
            assertLoopKeptCycling("cameras reinstalled");
            rec.armed = false;
            report.add(String.format("vision loss: corrected reference steps at most %.2e rad beyond the rate limit"
                    + " (%d samples), program reference moved %.2e rad", rec.maxExcess, rec.samples, rec.maxRefMove));
            assertTrue(rec.maxExcess <= 1e-9, "the robot's reference stepped " + rec.maxExcess + " rad beyond the rate limit");
            assertTrue(rec.maxRefMove == 0.0, "the program's reference moved by " + rec.maxRefMove + " rad at rest");
            assertEquals(null, rec.error.get());
        }
        double back = settledTrueError("correction on after vision came back", 3, 0.05, 120_000);
        report.add(String.format("after vision came back: true error %.4f mm (off was %.4f mm)", back, errOffMm));
        assertTrue(back <= errOffMm / 5, "true error after vision came back " + back + " mm, off was " + errOffMm + " mm");
    }

    @Test
    @Order(5)
    void debugMonitorInstalledReadsTheCorrectionAndIsRemovedWhileTheCellKeepsCycling() throws Exception {
        // The shipped debug monitor watches the sample pair; an engineer's variant of its
        // contract watches tcp-correction's error and correction instead (bundles/debug-monitor).
        Path monitor = rt.dir.resolve("debug-monitor-tcp.jar");
        Jars.withContract(DebugMonitorIT.DEBUGMON, monitor,
                c -> c.replace("<bind component=\"sample-counter\" port=\"count\"/>",
                        "<bind component=\"tcp-correction\" port=\"error\"/>")
                        .replace("<bind component=\"sample-scaler\" port=\"y\"/>",
                                "<bind component=\"tcp-correction\" port=\"correction\"/>"));
        markLoop("before the debug monitor");
        long id = rt.installAndStart(monitor);
        rt.awaitState("ACTIVE", T, "debug-monitor");
        String bindings = rt.cmd("arflex:bindings");
        assertTrue(bindings.contains("debug-monitor.m0 <- tcp-correction.error"), bindings);
        assertTrue(bindings.contains("debug-monitor.m1 <- tcp-correction.correction"), bindings);
        assertLoopKeptCycling("debug monitor installed");
        try (CellPorts.State m0 = new CellPorts.State(seg("debug-monitor", "m0_last"), CellPorts.SAMPLE);
                CellPorts.State m1 = new CellPorts.State(seg("debug-monitor", "m1_last"), CellPorts.SAMPLE);
                CellPorts.State err = new CellPorts.State(seg("tcp-correction", "error"), CellPorts.SAMPLE);
                CellPorts.State size = new CellPorts.State(seg("tcp-correction", "correction"), CellPorts.SAMPLE)) {
            // m0_last is a verbatim copy of tcp-correction's error output: the same seq, the same value.
            int[] matched = {0};
            long[] last = {-1};
            rt.waitUntil("the monitor showing 2 vision measurements of tcp-correction", 120_000, () -> {
                CellPorts.Sample a = CellPorts.Sample.of(m0.read());
                CellPorts.Sample b = CellPorts.Sample.of(err.read());
                if (a != null && b != null && a.seq() == b.seq() && a.seq() != last[0]) {
                    assertEquals(b.value(), a.value(), 0.0, "m0_last vs tcp-correction.error of seq " + a.seq());
                    last[0] = a.seq();
                    matched[0]++;
                }
                return matched[0] >= 2;
            });
            CellPorts.Sample first = CellPorts.Sample.of(m1.read());
            rt.waitUntil("the monitor following tcp-correction's correction", T, () -> {
                CellPorts.Sample a = CellPorts.Sample.of(m1.read());
                CellPorts.Sample b = CellPorts.Sample.of(size.read());
                return a != null && b != null && first != null && a.seq() > first.seq() && a.seq() <= b.seq();
            });
            report.add("debug monitor: m0_last = tcp-correction.error (" + matched[0] + " measurements, last "
                    + CellPorts.Sample.of(m0.read()) + "), m1_last = " + CellPorts.Sample.of(m1.read()));
        }
        assertLoopKeptCycling("debug monitor watching");
        assertEquals("", rt.cmd("uninstall " + id));
        rt.waitUntil("debug-monitor gone (instance, process, ports)", T, () -> {
            Map<String, Object> i = rt.instance("debug-monitor");
            boolean gone = i == null || "DESTROYED".equals(i.get("state"));
            return gone && !Files.exists(seg("debug-monitor", "m0_last"))
                    && Runtime.rtProcesses(rt.rid).stream().noneMatch(p -> p.contains("--instance debug-monitor"));
        });
        assertLoopKeptCycling("debug monitor uninstalled");
    }

    @Test
    @Order(6)
    void aTripTheTestDidNotCauseFailsItWithItsCause() throws Exception {
        // A push the test does not announce (D77): the operator must fail, naming the trip's
        // flags, force and sim-robot's releases before it, instead of resetting it.
        CellRig.set(rt, "sim-robot", "push_duration_ms", "200");
        CellRig.set(rt, "sim-robot", "push_force_n", "400");
        rt.waitUntil("the guard tripped by the push", 30_000, () -> CellRig.awaitingReset(rt).contains("force-guard"));
        CellRig.set(rt, "sim-robot", "push_force_n", "0");
        org.opentest4j.AssertionFailedError e = org.junit.jupiter.api.Assertions.assertThrows(
                org.opentest4j.AssertionFailedError.class, operator::tickNow, "the operator reset a trip nobody announced");
        report.add("an unannounced trip fails the test: " + e.getMessage().replace('\n', ';'));
        assertTrue(e.getMessage().contains("the force guard tripped and the test did not cause it: FORCE_LIMIT|RESET_REQUIRED at "),
                e.getMessage());
        assertTrue(e.getMessage().contains("sim-robot: ") && e.getMessage().contains("release gaps"), e.getMessage());
        assertTrue(CellRig.awaitingReset(rt).contains("force-guard"), "the operator reset it anyway");
        // announced afterwards, it is reset as an expected one, and the cell waits for nothing
        operator.expectTrip("the unannounced push, now accounted for");
        rt.waitUntil("nothing waiting for a reset or a fresh command", 60_000, () -> {
            operator.tickNow();
            return CellRig.awaitingReset(rt).isEmpty() && CellRig.awaitingCommand(rt).isEmpty();
        });
    }
}
