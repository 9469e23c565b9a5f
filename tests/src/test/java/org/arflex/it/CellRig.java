package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.nio.ByteOrder;
import java.nio.MappedByteBuffer;
import java.nio.channels.FileChannel;
import java.nio.file.Files;
import java.nio.file.Path;
import java.nio.file.StandardOpenOption;
import java.util.ArrayList;
import java.util.List;
import java.util.Map;
import java.util.concurrent.CopyOnWriteArrayList;
import java.util.function.Consumer;

/**
 * What the cell's integration tests (ForceGuardIT, TeachIT, ToolSwapIT) share: the cell bundles'
 * jars, installing the simulated arm with its motion path, and raw reads of the cell's state
 * ports (arflex.JointRef, JointState, Wrench, SafetyState, Sample) from shared memory.
 */
final class CellRig {

    private CellRig() {
    }

    static final long T = 60_000;

    static final Path SIM_ROBOT = Components.jar("sim-robot");
    static final Path TRAJECTORY = Components.jar("trajectory");
    static final Path FORCE_GUARD = Components.jar("force-guard");
    static final Path TEACH = Components.jar("teach");
    static final Path GRIPPER = Components.jar("tool-gripper");
    static final Path SPINDLE = Components.jar("tool-spindle");
    static final Path TCP_CORRECTION = Components.jar("tcp-correction");

    static void assertBuilt(Path... jars) {
        for (Path j : jars) {
            assertTrue(Files.isRegularFile(j), "cell bundle not built: " + j);
        }
    }

    /**
     * Installs and starts the simulated arm. When its contract binds {@code joint_ref} to the
     * TCP correction (the cell's wiring: motion -> tcp-correction -> robot), the correction is
     * installed too, so that a motion source reaches the arm; without vision it passes the
     * reference through unchanged. Returns the names of what was installed.
     */
    static List<String> installArm(Runtime rt) {
        List<String> names = new ArrayList<>();
        rt.installAndStart(SIM_ROBOT);
        names.add("sim-robot");
        // the robot holds without a fresh safety input (SAFETY.md 1): the guard is part of an arm
        assertBuilt(FORCE_GUARD);
        rt.installAndStart(FORCE_GUARD);
        names.add("force-guard");
        rt.waitUntil("sim-robot known", T, () -> rt.instance("sim-robot") != null);
        String info = rt.cmd("arflex:info sim-robot");
        String jr = info.lines().filter(l -> l.contains("in joint_ref")).findFirst().orElse("");
        if (jr.contains("correction")) {
            assertBuilt(TCP_CORRECTION);
            rt.installAndStart(TCP_CORRECTION);
            names.add("tcp-correction");
        }
        return names;
    }

    /** What the runtime's conf/cell.gosh (the main job's cell) starts and sets, in its order. */
    record Gosh(List<Path> starts, List<String> settings) {
    }

    /** Reads the runtime's conf/cell.gosh; a line of another kind than start/arflex:set/comment fails. */
    static Gosh cellGosh(Runtime rt) throws IOException {
        List<Path> starts = new ArrayList<>();
        List<String> settings = new ArrayList<>();
        for (String line : Files.readAllLines(rt.dir.resolve("conf/cell.gosh"), java.nio.charset.StandardCharsets.UTF_8)) {
            String l = line.strip();
            if (l.startsWith("start file:@CELL@/")) {
                starts.add(rt.dir.resolve("cell").resolve(l.substring("start file:@CELL@/".length())));
            } else if (l.startsWith("arflex:set ")) {
                settings.add(l);
            } else {
                assertTrue(l.isEmpty() || l.startsWith("#"), "cell.gosh line not understood: " + l);
            }
        }
        return new Gosh(starts, settings);
    }

    /**
     * Components waiting for an operator reset: restarted ones (the DTO's awaitingReset) and
     * those whose RT half latched RESET_REQUIRED itself (a moving component after a runtime
     * heartbeat loss, the force guard after a trip; read from the control block).
     */
    /** Motion sources that hold after a reset until a fresh command (DTO holding, SAFETY.md 2). */
    static List<String> awaitingCommand(Runtime rt) {
        return Runtime.names(rt.dto(), i -> String.valueOf(i.get("holding")).startsWith("stopped: waits for a fresh command"));
    }

    /**
     * The start-up check of a test that builds an arm (D77): before anything moves, a component
     * may wait for a reset after a stall of the runtime while it was installed (issue 15 finding
     * 6: the heartbeat lost). That is reset, named in one printed line ({@code who}: what waited
     * and why); a force trip of the guard is not: it fails the test with its force and flags.
     * Returns the components reset.
     */
    static List<String> resetBeforeTheTest(Runtime rt, String who) throws IOException {
        List<String> waiting = awaitingReset(rt);
        if (waiting.isEmpty()) {
            return waiting;
        }
        Path guard = rt.segment("force-guard", "safety");
        if (waiting.contains("force-guard") && Files.exists(guard)) {
            try (Port p = new Port(guard, SAFETY_SIZE)) {
                Safety s = Safety.of(p.read());
                org.junit.jupiter.api.Assertions.assertFalse(s != null && (s.flags() & 1) != 0,
                        () -> who + ": the guard tripped before the test: " + s.causes() + " at " + s.forceNorm() + " N: " + s);
            }
        }
        StringBuilder why = new StringBuilder();
        for (Map<String, Object> i : Runtime.list(rt.dto(), "instances")) {
            if (waiting.contains(i.get("name"))) {
                why.append(why.length() > 0 ? "; " : "").append(i.get("name")).append(": ").append(i.get("holding"));
            }
        }
        System.out.println(who + ": before the test, awaiting a reset, not a trip (" + why + ") -> "
                + rt.cmd("arflex:reset --cell"));
        return waiting;
    }

    static List<String> awaitingReset(Runtime rt) {
        return Runtime.names(rt.dto(), i -> Boolean.TRUE.equals(i.get("awaitingReset"))
                || (CellPorts.ctlFlags(Path.of("/dev/shm/arflex." + rt.rid + "." + i.get("name") + ".ctl"))
                        & CellPorts.FLAG_RESET_REQUIRED) != 0);
    }

    /**
     * A runtime on a private copy of the assembly (under arflex.it.work) whose configuration
     * makes it an evaluation run: simulated robots publish their ground truth. {@code copy} is
     * the folder of the copy; delete it after the runtime is closed.
     */
    static Runtime evaluationRuntime(String name, Path copy) throws IOException, InterruptedException {
        Path assembly = Path.of(System.getProperty("arflex.it.runtime"));
        Runtime.deleteTree(copy);
        Runtime.copyTree(assembly, copy);
        Files.writeString(copy.resolve("conf/config.properties"),
                "\n# " + name + ": an evaluation run (ground truth of simulated robots)\narflex.evaluation=true\n",
                java.nio.charset.StandardCharsets.UTF_8, java.nio.file.StandardOpenOption.APPEND);
        String old = System.getProperty("arflex.it.runtime");
        System.setProperty("arflex.it.runtime", copy.toString());
        try {
            return new Runtime(name);
        } finally {
            System.setProperty("arflex.it.runtime", old);
        }
    }

    /**
     * The operator at the cell (D77): at most once a second, looks at what waits for a reset. A
     * trip of the force guard the test announced ({@link #expectTrip}) is reset and counted; any
     * other component waiting for a reset FAILS the test, with its cause: for the guard, the
     * trip's flags, force and sim-robot's release gaps over the 200 ms before it (TripWatch); for
     * another, its holding reason and control flags. Nothing is reset that the test did not cause
     * (the runtime's heartbeat, once reset here "on this shared machine", is not lost: D75 measured
     * its writer's gaps under 43 ms against the 100 ms timeout). A lenient operator (a bench that
     * measures the stops a change causes, ReconfigBench) resets everything and counts it by name.
     */
    static final class Operator implements AutoCloseable {
        final Map<String, Integer> resets = new java.util.TreeMap<>();
        /** Resets so far, all components together. */
        int total;
        private final Runtime rt;
        private final boolean lenient;
        private long last;
        /** The operator paused the program for the arm to take up its reference. */
        private boolean paused;
        /** Trips the test announced and has not yet seen reset, and why. */
        private final java.util.Deque<String> expected = new java.util.ArrayDeque<>();
        private TripWatch watch;

        private String param(String n, String p) {
            String v = rt.cmd("arflex:get " + n + " " + p).strip();
            return v.substring(v.lastIndexOf(' ') + 1);
        }

        Operator(Runtime rt) {
            this(rt, false);
        }

        private Operator(Runtime rt, boolean lenient) {
            this.rt = rt;
            this.lenient = lenient;
        }

        /** An operator that resets whatever waits and counts it by name (benches measuring stops). */
        static Operator lenient(Runtime rt) {
            return new Operator(rt, true);
        }

        /** The test is about to trip the guard on purpose ({@code why}): the next trip is reset, not failed. */
        void expectTrip(String why) {
            watch();
            expected.addLast(why);
        }

        private TripWatch watch() {
            if (watch == null) {
                try {
                    watch = TripWatch.open(rt);
                } catch (IOException e) {
                    throw new java.io.UncheckedIOException(e);
                }
            }
            return watch;
        }

        /** The reset of {@code n} the test did not cause: the failure's message. */
        private String unexpected(String n) {
            if ("force-guard".equals(n)) {
                TripWatch w = watch();
                return "the force guard tripped and the test did not cause it: "
                        + (w == null ? "(no trip recorder: force-guard or sim-robot has no output)" : w.explain(w.trip()));
            }
            Map<String, Object> i = Runtime.list(rt.dto(), "instances").stream().filter(x -> n.equals(x.get("name")))
                    .findFirst().orElse(Map.of());
            int flags = CellPorts.ctlFlags(Path.of("/dev/shm/arflex." + rt.rid + "." + n + ".ctl"));
            return n + " waits for an operator reset the test did not cause: holding '" + i.get("holding") + "', ctl flags 0x"
                    + Integer.toHexString(flags) + ", awaitingReset " + i.get("awaitingReset");
        }

        @Override
        public void close() throws Exception {
            if (watch != null) {
                watch.close();
            }
        }

        /** Resets what waits, unless that was checked less than a second ago. */
        void tick() {
            if (System.nanoTime() - last >= 1_000_000_000L) {
                tickNow();
            }
        }

        /** Resets what waits for a reset, now. */
        void tickNow() {
            last = System.nanoTime();
            if (!lenient) {
                watch(); // from the first look on, so that a trip has its 200 ms before it recorded
            }
            List<String> reset = awaitingReset(rt);
            for (String n : reset) {
                String why = n;
                if (!lenient) {
                    if (!"force-guard".equals(n) || expected.isEmpty()) {
                        org.junit.jupiter.api.Assertions.fail(unexpected(n));
                    }
                    why = n + " (" + expected.removeFirst() + ")";
                    if (watch != null) {
                        watch.forget();
                    }
                }
                rt.cmd("arflex:reset " + n);
                resets.merge(why, 1, Integer::sum);
                total++;
            }
            if (!reset.isEmpty()) {
                return; // the fresh command at the next tick, once the arm has taken up its reference
            }
            // a reset permits motion, it does not start it: the operator's fresh command, once the
            // arm has taken up its reference again (after a stop the robot takes one at rest only:
            // a program started before that moves its reference away and the arm keeps holding)
            Map<String, Object> dto = rt.dto();
            if (!Runtime.names(dto, i -> String.valueOf(i.get("holding")).startsWith("holds: waits for a reference"))
                    .isEmpty()) {
                // a program that kept running while the robot stopped (a reset latched by a
                // heartbeat lost at start-up) moves its reference on: pause it so that the
                // reference comes to rest, the arm takes it up, then go on
                if (!Runtime.names(dto, i -> "trajectory".equals(i.get("name")) && i.get("holding") == null
                        && "ACTIVE".equals(i.get("state"))).isEmpty() && "true".equals(param("trajectory", "run"))) {
                    rt.cmd("arflex:set trajectory run false");
                    paused = true;
                }
                return; // the next tick
            }
            if (paused) {
                paused = false;
                rt.cmd("arflex:set trajectory run true");
            }
            for (String n : awaitingCommand(rt)) {
                if (n.startsWith("tool-")) {
                    // a tool's fresh command is a write of its command (the level it had)
                    rt.cmd("arflex:set " + n + " command " + rt.cmd("arflex:get " + n + " command").strip());
                } else {
                    rt.cmd("arflex:set " + n + " run true");
                }
            }
        }
    }

    /** The TRUE tool-centre error (mm): the simulator's ground truth against the nominal model at the reference. */
    static double trueErrorMm(CellPorts.State truth, CellPorts.State ref) {
        CellPorts.Truth t = CellPorts.Truth.of(truth.read());
        CellPorts.Joints r = CellPorts.Joints.of(ref.read(), false);
        org.junit.jupiter.api.Assertions.assertNotNull(t, "no ground truth");
        org.junit.jupiter.api.Assertions.assertNotNull(r, "no reference");
        return 1e3 * org.arflex.drcr.impl.shell.NominalArm.distance(t.p(), org.arflex.drcr.impl.shell.NominalArm.tcp(r.q()));
    }

    /** The cell's ports the accuracy measurements read (mapped read-only). */
    record AccuracyPorts(CellPorts.State truth, CellPorts.State ref, CellPorts.State js, CellPorts.State err)
            implements AutoCloseable {
        static AccuracyPorts open(Runtime rt) throws IOException {
            return new AccuracyPorts(new CellPorts.State(rt.segment("sim-robot", "truth"), CellPorts.TRUTH),
                    new CellPorts.State(rt.segment("trajectory", "joint_ref"), CellPorts.JOINT_REF),
                    new CellPorts.State(rt.segment("sim-robot", "joint_state"), CellPorts.JOINT_STATE),
                    new CellPorts.State(rt.segment("tcp-correction", "error"), CellPorts.SAMPLE));
        }

        @Override
        public void close() throws IOException {
            for (CellPorts.State p : new CellPorts.State[] {truth, ref, js, err}) {
                p.close();
            }
        }
    }

    /**
     * Waits (up to {@code timeoutMs}) until the true error has settled: after each new vision
     * measurement (tcp-correction's error output) the TRUE error, until {@code n} in a row lie
     * within {@code bandMm} of the one before with the arm at rest. The operator ticks while it
     * waits. Returns every (seconds since {@code sinceNs}, error mm) seen, the settled run last.
     */
    static List<double[]> settle(Runtime rt, Operator operator, AccuracyPorts p, int n, double bandMm, long sinceNs,
            long timeoutMs) {
        List<double[]> all = new ArrayList<>();
        int[] run = {0};
        long[] lastSeq = {-1};
        double[] prev = {Double.NaN};
        rt.waitUntil(n + " vision measurements in a row within " + bandMm + " mm of each other", timeoutMs, () -> {
            operator.tick();
            CellPorts.Sample e = CellPorts.Sample.of(p.err().read());
            long seq = e == null ? 0 : e.seq();
            if (seq == lastSeq[0]) {
                return false;
            }
            lastSeq[0] = seq;
            CellPorts.Joints s = CellPorts.Joints.of(p.js().read(), true);
            double now = trueErrorMm(p.truth(), p.ref());
            all.add(new double[] {(System.nanoTime() - sinceNs) / 1e9, now});
            run[0] = s == null || s.maxAbsVelocity() > 1e-3 || !(Math.abs(now - prev[0]) <= bandMm) ? 1 : run[0] + 1;
            prev[0] = now;
            return run[0] >= n;
        });
        return all;
    }

    /** The mean error of the last {@code n} entries of {@link #settle}'s result. */
    static double meanOfLast(List<double[]> settled, int n) {
        return settled.subList(settled.size() - n, settled.size()).stream().mapToDouble(x -> x[1]).average().orElseThrow();
    }

    /** The input of sim-robot that carries the motion reference, as arflex:bindings prints it. */
    static boolean armFollows(Runtime rt, String motionSource) {
        String b = rt.cmd("arflex:bindings");
        if (b.contains("sim-robot.joint_ref <- " + motionSource + ".joint_ref")) {
            return true;
        }
        return b.contains("sim-robot.joint_ref <- tcp-correction.corrected")
                && b.contains("tcp-correction.reference <- " + motionSource + ".joint_ref");
    }

    /** Installs a bundle without starting it; waits until the DRCR knows its instance. */
    static long installOnly(Runtime rt, Path jar, String instance) {
        long id = rt.install(jar);
        rt.waitUntil(instance + " known", T, () -> rt.instance(instance) != null);
        return id;
    }

    /**
     * Starts the trajectory on program {@code n} of the runtime's data directory. Parameters
     * set while a component is only Installed are reset to the contract's defaults when it
     * starts (the DRCR today), so the program is chosen once it runs: paused at once, switched
     * to {@code n} (taken at the standstill), resumed. {@code params}: name, value, ... set
     * while paused. Returns the bundle id.
     */
    static long startTrajectory(Runtime rt, int n, String... params) throws IOException {
        long id = rt.installAndStart(TRAJECTORY);
        rt.awaitState("ACTIVE", T, "trajectory");
        set(rt, "trajectory", "run", "false");
        set(rt, "trajectory", "program", Integer.toString(n));
        for (int i = 0; i + 1 < params.length; i += 2) {
            set(rt, "trajectory", params[i], params[i + 1]);
        }
        try (Port ref = new Port(rt.segment("trajectory", "joint_ref"), REF_SIZE)) {
            long[] still = {0, 0};
            double[][] last = {null};
            rt.waitUntil("the trajectory at a standstill (paused)", T, () -> {
                Ref r = Ref.of(ref.read());
                if (r == null) {
                    return false;
                }
                if (last[0] != null && java.util.Arrays.equals(last[0], r.q())) {
                    if (still[0] == 0) {
                        still[0] = r.seq();
                    }
                    still[1] = r.seq();
                } else {
                    still[0] = 0;
                }
                last[0] = r.q();
                return still[0] != 0 && still[1] - still[0] >= 50;
            });
        }
        set(rt, "trajectory", "run", "true");
        return id;
    }

    static void set(Runtime rt, String inst, String param, String value) {
        String r = rt.cmd("arflex:set " + inst + " " + param + " " + value);
        assertTrue(r.startsWith(inst + "." + param + " = "), "arflex:set " + inst + " " + param + " " + value + ": " + r);
    }

    /** Uninstalls a bundle and waits until its instance, process and ports are gone. */
    static void uninstall(Runtime rt, long bundle, String instance, String port) {
        assertEquals("", rt.cmd("uninstall " + bundle));
        rt.waitUntil(instance + " gone (instance, process, port)", T, () -> {
            Map<String, Object> i = rt.instance(instance);
            boolean gone = i == null || "DESTROYED".equals(i.get("state"));
            return gone && !Files.exists(rt.segment(instance, port))
                    && Runtime.rtProcesses(rt.rid).stream().noneMatch(p -> p.contains("--instance " + instance + " "));
        });
    }

    @SuppressWarnings("unchecked")
    static long cycles(Runtime rt, String name) {
        Map<String, Object> i = rt.instance(name);
        Map<String, Object> st = i == null ? null : (Map<String, Object>) i.get("stats");
        return st == null ? -1 : ((Number) st.get("cycles")).longValue();
    }

    /**
     * One state port mapped read-only (rt-core ABI.md §4: slot 0's seq at Ports.SLOT0_SEQ, odd
     * while the writer writes, the value at Ports.SLOT0_VALUE). Every cell type starts with t_ns/seq (or
     * seq/t_ns for arflex.Sample) followed by f64/u32 fields read by offset.
     */
    static final class Port implements AutoCloseable {
        final Path path;
        private final FileChannel ch;
        private final MappedByteBuffer b;
        private final int size;

        Port(Path segment, int valueSize) throws IOException {
            path = segment;
            ch = FileChannel.open(segment, StandardOpenOption.READ);
            // a state block can be larger than a page (arflex.TeachState: 6456 bytes)
            b = ch.map(FileChannel.MapMode.READ_ONLY, 0, Math.max(4096, Math.min(ch.size(), Ports.SLOT0_VALUE + valueSize)));
            b.order(ByteOrder.LITTLE_ENDIAN);
            size = valueSize;
        }

        /** The current value's bytes (little-endian), or null (never written, or torn on every try). */
        java.nio.ByteBuffer read() {
            byte[] v = new byte[size];
            for (int attempt = 0; attempt < 100; attempt++) {
                long s1 = b.getLong(Ports.SLOT0_SEQ);
                if (s1 == 0) {
                    return null;
                }
                if ((s1 & 1) != 0) {
                    Thread.onSpinWait();
                    continue;
                }
                b.get(Ports.SLOT0_VALUE, v);
                if (b.getLong(Ports.SLOT0_SEQ) == s1) {
                    return java.nio.ByteBuffer.wrap(v).order(ByteOrder.LITTLE_ENDIAN);
                }
            }
            return null;
        }

        @Override
        public void close() throws IOException {
            ch.close();
        }
    }

    /** arflex.JointRef: t_ns, seq, q[6]. */
    record Ref(long tNs, long seq, double[] q) {
        static Ref of(java.nio.ByteBuffer v) {
            return v == null ? null : new Ref(v.getLong(0), v.getLong(8), doubles(v, 16, 6));
        }
    }

    /** arflex.JointState: t_ns, seq, q[6], qd[6], tau[6]. */
    record JointState(long tNs, long seq, double[] q, double[] qd) {
        static JointState of(java.nio.ByteBuffer v) {
            return v == null ? null : new JointState(v.getLong(0), v.getLong(8), doubles(v, 16, 6), doubles(v, 64, 6));
        }

        /** The largest joint speed (rad/s). */
        double maxSpeed() {
            double m = 0;
            for (double x : qd) {
                m = Math.max(m, Math.abs(x));
            }
            return m;
        }
    }

    /** arflex.Wrench: t_ns, seq, force[3], torque[3]. */
    record Wrench(long tNs, long seq, double[] force) {
        static Wrench of(java.nio.ByteBuffer v) {
            return v == null ? null : new Wrench(v.getLong(0), v.getLong(8), doubles(v, 16, 3));
        }

        double norm() {
            return Math.sqrt(force[0] * force[0] + force[1] * force[1] + force[2] * force[2]);
        }
    }

    /** arflex.SafetyState: t_ns, seq, mode u32, flags u32, power_scale, force_norm, force_limit. */
    record Safety(long tNs, long seq, int mode, int flags, double powerScale, double forceNorm, double forceLimit) {
        static final int NORMAL = 0;
        static final int PROTECTIVE_STOP = 2;

        /** The names of the flags set (arflex.SafetyState): a force trip, a lost heartbeat, a reset awaited (D75). */
        String causes() {
            String[] names = {"FORCE_LIMIT", "HEARTBEAT_LOST", "RESET_REQUIRED"};
            java.util.StringJoiner j = new java.util.StringJoiner("|");
            for (int b = 0; b < names.length; b++) {
                if ((flags & (1 << b)) != 0) {
                    j.add(names[b]);
                }
            }
            return j.length() == 0 ? "no flag" : j.toString();
        }

        static Safety of(java.nio.ByteBuffer v) {
            return v == null ? null
                    : new Safety(v.getLong(0), v.getLong(8), v.getInt(16), v.getInt(20), v.getDouble(24), v.getDouble(32),
                            v.getDouble(40));
        }
    }

    /** arflex.Sample: seq, t_ns, value. */
    record Sample(long seq, long tNs, double value) {
        static Sample of(java.nio.ByteBuffer v) {
            return v == null ? null : new Sample(v.getLong(0), v.getLong(8), v.getDouble(16));
        }
    }

    static final int REF_SIZE = 64;
    static final int JOINT_STATE_SIZE = 160;
    static final int WRENCH_SIZE = 64;
    static final int SAFETY_SIZE = 48;
    static final int SAMPLE_SIZE = 24;

    static double[] doubles(java.nio.ByteBuffer v, int off, int n) {
        double[] d = new double[n];
        for (int i = 0; i < n; i++) {
            d[i] = v.getDouble(off + 8 * i);
        }
        return d;
    }

    /** Largest |a_j - b_j|. */
    static double maxDiff(double[] a, double[] b) {
        double m = 0;
        for (int j = 0; j < a.length; j++) {
            m = Math.max(m, Math.abs(a[j] - b[j]));
        }
        return m;
    }

    /** Values in arrival order, shared between the recorder thread and the test. */
    static final class Trace<V> {
        private final List<V> values = new ArrayList<>();

        synchronized void add(V v) {
            values.add(v);
        }

        synchronized int size() {
            return values.size();
        }

        /** The newest value, or null. */
        synchronized V last() {
            return values.isEmpty() ? null : values.get(values.size() - 1);
        }

        synchronized V get(int i) {
            return values.get(i);
        }

        /** A copy of the values from index {@code mark} on (one consistent view). */
        synchronized List<V> since(int mark) {
            return new ArrayList<>(values.subList(Math.min(mark, values.size()), values.size()));
        }

        /** A copy of everything so far. */
        synchronized List<V> snapshot() {
            return new ArrayList<>(values);
        }
    }

    /** KR 210-class joint speed limits the trajectory's limiter holds (rad/s). */
    static final double[] VMAX = {Math.toRadians(123), Math.toRadians(115), Math.toRadians(112), Math.toRadians(179),
            Math.toRadians(172), Math.toRadians(219)};

    /**
     * Polls a set of ports in a thread of its own every ~200 us (the ports change every
     * millisecond; a value overwritten before a poll is missed, which the tests account for by
     * checking seq gaps) and hands every new value (by seq) to its consumer.
     */
    static final class Recorder implements AutoCloseable {
        private final List<Runnable> polls = new CopyOnWriteArrayList<>();
        private final Thread thread;
        private volatile boolean stop;
        volatile Throwable error;

        Recorder() {
            thread = new Thread(this::run, "cell-recorder");
            thread.setDaemon(true);
        }

        <V> void add(Port p, java.util.function.Function<java.nio.ByteBuffer, V> decode,
                java.util.function.ToLongFunction<V> seqOf, Consumer<V> sink) {
            long[] last = {0};
            polls.add(() -> {
                V v = decode.apply(p.read());
                if (v != null && seqOf.applyAsLong(v) != last[0]) {
                    last[0] = seqOf.applyAsLong(v);
                    sink.accept(v);
                }
            });
        }

        /**
         * Waits for a joint reference segment {@code seg} that a command in progress creates (a
         * change set's new half), until it exists with its header or {@code command} is done,
         * within {@link #T}; records its values into {@code sink} from then on. Returns the port,
         * or null when the command ended without it.
         */
        Port recordRefsWhenItAppears(Path seg, java.util.concurrent.Future<?> command, Consumer<Ref> sink)
                throws java.io.IOException {
            long deadline = System.nanoTime() + T * 1_000_000L;
            while (!(Files.exists(seg) && Files.size(seg) >= 4096) && !command.isDone()) {
                org.junit.jupiter.api.Assertions.assertTrue(System.nanoTime() - deadline < 0, "no segment " + seg);
                java.util.concurrent.locks.LockSupport.parkNanos(200_000);
            }
            if (!(Files.exists(seg) && Files.size(seg) >= 4096)) {
                return null;
            }
            Port np = new Port(seg, REF_SIZE);
            add(np, Ref::of, Ref::seq, sink);
            return np;
        }

        void start() {
            thread.start();
        }

        private void run() {
            try {
                while (!stop) {
                    for (Runnable r : polls) {
                        r.run();
                    }
                    // ~200 us between polls: most 1 ms values are seen without taking a core
                    java.util.concurrent.locks.LockSupport.parkNanos(200_000);
                }
            } catch (Throwable t) {
                error = t;
            }
        }

        @Override
        public void close() throws InterruptedException {
            stop = true;
            thread.join(10_000);
        }
    }

    /**
     * The largest step of a reference per cycle of its source ({@link ChangeSetIT#perSourceCycle})
     * before index {@code mark} and from it on: {before, after}.
     */
    static double[] stepsBeforeAndAfter(List<Ref> refs, int mark) {
        double before = 0;
        double after = 0;
        for (int i = 1; i < refs.size(); i++) {
            double s = ChangeSetIT.perSourceCycle(refs.get(i - 1), refs.get(i));
            if (i < mark) {
                before = Math.max(before, s);
            } else {
                after = Math.max(after, s);
            }
        }
        return new double[] {before, after};
    }

    /** The guard's output with the largest force. */
    static Safety worst(List<Safety> ss) {
        return ss.stream().max(java.util.Comparator.comparingDouble(Safety::forceNorm)).orElseThrow();
    }

    /** The guard's first output that is not NORMAL, or null. */
    static Safety tripped(List<Safety> ss) {
        return ss.stream().filter(x -> x.mode() != Safety.NORMAL).findFirst().orElse(null);
    }
}
