package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Locale;
import java.util.Map;
import java.util.TreeMap;
import java.util.TreeSet;
import java.util.concurrent.locks.LockSupport;
import org.junit.jupiter.api.Test;

/**
 * Benchmark, not a test (run on purpose: {@code ./arflex bench cell}, see tests/README.md): the
 * main job's cell (the runtime's own conf/cell.gosh, the robot looping through the demonstration
 * program) measured in alternating windows of equal length. A <b>control</b> window changes
 * nothing. A <b>change</b> window repeats, back to back, the structural changes of issue 7 while
 * everything runs ({@link #CHANGES}): a tool swap, a vision loss, a debug monitor on
 * tcp-correction installed, read and uninstalled, a parameter change. A poller reads the DTO at
 * 2 Hz in both kinds of window, so the management load of watching is the same. Each change is
 * also measured alone (counters read just before and just after it), which says which change
 * costs what. The RT halves lock their memory as in the main job.
 *
 * <p>Per component that stays (sim-robot, trajectory, tcp-correction, force-guard, vision, the
 * sample pair) and window: cycles against the periods that passed, deadline overruns, WCET
 * overruns, wake-up latency p99 and max (from the control block's histogram, the difference
 * between the window's ends), restarts, safe-mode episodes. Printed as a table (control summed
 * against change summed, and the extra overruns) and written to target/bench/cell.json.
 *
 * <p>Properties: {@code arflex.bench.seconds} (window length, default 30),
 * {@code arflex.bench.rounds} (control + change pairs, default 3).
 */
class CellChurnBench {

    static final String[] MEASURED = {"sim-robot", "trajectory", "tcp-correction", "force-guard", "vision",
            "sample-counter", "sample-scaler"};
    static final long T = 120_000;
    /**
     * The changes of a change window, in turn: a tool swap in two halves (the mounted tool's
     * bundle uninstalled; the other tool's installed and bound), a vision loss in two halves
     * (the cameras' bundle uninstalled; reinstalled and rebound), a debug monitor on
     * tcp-correction installed, read and uninstalled, a parameter set on a running component.
     */
    static final String[] CHANGES = {"tool unmounted", "tool mounted", "cameras removed", "cameras back", "debug monitor",
        "parameter"};

    Runtime rt;
    final Map<String, Long> bundles = new LinkedHashMap<>();
    String tool = "tool-gripper";
    /** Index of the next change in {@link #CHANGES} (goes on across windows). */
    int next;
    int gain = 2;
    /** Names seen in safe mode or awaiting a reset by the poller, for the current window. */
    final java.util.Set<String> safeSeen = java.util.Collections.synchronizedSet(new TreeSet<>());

    /** A component's counters at one instant (from the DTO). */
    record Snap(long pid, long cycles, long overruns, long wcet, long binNs, Map<Integer, Long> hist, long overflow,
            long tNs) {
        @SuppressWarnings("unchecked")
        static Snap of(Map<String, Object> inst, long tNs) {
            Map<String, Object> st = (Map<String, Object>) inst.get("stats");
            Map<Integer, Long> h = new TreeMap<>();
            List<Object> bins = (List<Object>) st.get("latencyHistBins");
            List<Object> counts = (List<Object>) st.get("latencyHistCounts");
            if (bins != null) {
                for (int i = 0; i < bins.size(); i++) {
                    h.put(((Number) bins.get(i)).intValue(), ((Number) counts.get(i)).longValue());
                }
            }
            return new Snap(((Number) inst.get("pid")).longValue(), num(st, "cycles"), num(st, "overruns"),
                    num(st, "wcetOverruns"), num(st, "histBinNs"), h, num(st, "latencyHistOverflow"), tNs);
        }

        static long num(Map<String, Object> m, String k) {
            Object v = m.get(k);
            return v == null ? 0 : ((Number) v).longValue();
        }
    }

    /** What one component did in one or more windows (sums). */
    static final class Tally {
        long cycles;
        long periods;
        long overruns;
        long wcet;
        long restarts;
        long safe;
        long overflow;
        long binNs;
        final Map<Integer, Long> hist = new TreeMap<>();

        void add(Snap a, Snap b, long periodNs, boolean wasSafe) {
            safe += wasSafe ? 1 : 0;
            if (a.pid != b.pid) {
                restarts++;
                return; // counters started again from zero in the new process: the window is not counted
            }
            periods += (b.tNs - a.tNs) / periodNs;
            cycles += b.cycles - a.cycles;
            overruns += b.overruns - a.overruns;
            wcet += b.wcet - a.wcet;
            overflow += b.overflow - a.overflow;
            binNs = b.binNs;
            b.hist.forEach((k, v) -> {
                long d = v - a.hist.getOrDefault(k, 0L);
                if (d > 0) {
                    hist.merge(k, d, Long::sum);
                }
            });
        }

        void addAll(Tally t) {
            cycles += t.cycles;
            periods += t.periods;
            overruns += t.overruns;
            wcet += t.wcet;
            restarts += t.restarts;
            safe += t.safe;
            overflow += t.overflow;
            binNs = Math.max(binNs, t.binNs);
            t.hist.forEach((k, v) -> hist.merge(k, v, Long::sum));
        }

        /** Upper bin edge (us) below which the fraction q of the window's wake-ups lie; +inf in the overflow. */
        double quantileUs(double q) {
            long n = overflow + hist.values().stream().mapToLong(Long::longValue).sum();
            if (n == 0) {
                return Double.NaN;
            }
            long need = (long) Math.ceil(q * n);
            long acc = 0;
            for (var e : hist.entrySet()) {
                acc += e.getValue();
                if (acc >= need) {
                    return (e.getKey() + 1) * binNs / 1e3;
                }
            }
            return Double.POSITIVE_INFINITY;
        }

        double maxUs() {
            if (overflow > 0) {
                return Double.POSITIVE_INFINITY;
            }
            return hist.isEmpty() ? Double.NaN : (((TreeMap<Integer, Long>) hist).lastKey() + 1) * binNs / 1e3;
        }

        String json() {
            return String.format(Locale.ROOT,
                    "{\"cycles\":%d,\"periods\":%d,\"overruns\":%d,\"wcet_overruns\":%d,\"restarts\":%d,"
                            + "\"windows_with_safe_mode\":%d,\"latency_p99_us\":%s,\"latency_max_us\":%s,"
                            + "\"latency_overflow\":%d,\"hist_bin_ns\":%d}",
                    cycles, periods, overruns, wcet, restarts, safe, num(quantileUs(0.99)), num(maxUs()), overflow, binNs);
        }

        static String num(double d) {
            return Double.isFinite(d) ? String.format(Locale.ROOT, "%.1f", d) : "null";
        }
    }

    Map<String, Snap> snapshot() {
        Map<String, Object> dto = rt.dto();
        long t = System.nanoTime();
        Map<String, Snap> m = new LinkedHashMap<>();
        for (String n : MEASURED) {
            Map<String, Object> i = Runtime.list(dto, "instances").stream().filter(x -> n.equals(x.get("name"))).findFirst()
                    .orElseThrow(() -> new AssertionError(n + " not in the cell"));
            assertEquals("ACTIVE", i.get("state"), n + " at a window's edge");
            m.put(n, Snap.of(i, t));
        }
        return m;
    }

    Map<String, Long> periods() {
        Map<String, Long> p = new LinkedHashMap<>();
        for (Map<String, Object> c : Runtime.list(rt.dto(), "contracts")) {
            p.put((String) c.get("name"), ((Number) c.get("periodNs")).longValue());
        }
        return p;
    }

    // ---- the changes ---------------------------------------------------------------------------

    Path cellJar(String file) {
        return rt.dir.resolve("cell").resolve(file);
    }

    void gone(String instance) {
        rt.waitUntil(instance + " gone", T, () -> {
            Map<String, Object> i = rt.instance(instance);
            return i == null || "DESTROYED".equals(i.get("state"));
        });
    }

    String otherTool() {
        return tool.equals("tool-gripper") ? "tool-spindle" : "tool-gripper";
    }

    /** First half of a tool swap: the mounted tool's bundle uninstalled (trajectory plans for the flange). */
    void toolOff() {
        assertEquals("", rt.cmd("uninstall " + bundles.remove(tool)));
        gone(tool);
        rt.waitUntil("trajectory.tool unbound", T, () -> !rt.cmd("arflex:bindings").contains("trajectory.tool <- "));
        tool = otherTool();
    }

    /** Second half: the other tool installed and bound. */
    void toolOn() {
        String jar = tool.equals("tool-gripper") ? "org.arflex.cell.tool.gripper.jar" : "org.arflex.cell.tool.spindle.jar";
        bundles.put(tool, rt.installAndStart(cellJar(jar)));
        rt.awaitState("ACTIVE", T, tool);
        rt.waitUntil("trajectory.tool bound to " + tool, T,
                () -> rt.cmd("arflex:bindings").contains("trajectory.tool <- " + tool + ".tool"));
    }

    /** Vision loss: the cameras' bundle uninstalled, their processes and ports gone. */
    void camerasOff() {
        assertEquals("", rt.cmd("uninstall " + bundles.remove("cameras")));
        for (int c = 0; c < 4; c++) {
            gone("sim-camera-" + c);
        }
        rt.waitUntil("vision unbound from the cameras", T, () -> !rt.cmd("arflex:bindings").contains("vision.cam"));
    }

    /** Vision back: the cameras reinstalled, ACTIVE, vision rebound to them. */
    void camerasOn() {
        bundles.put("cameras", rt.installAndStart(cellJar("org.arflex.sim.camera.jar")));
        rt.awaitState("ACTIVE", T, "sim-camera-0", "sim-camera-1", "sim-camera-2", "sim-camera-3");
        rt.waitUntil("vision rebound to the four cameras", T, () -> {
            String b = rt.cmd("arflex:bindings");
            return b.contains("vision.cam0 <- sim-camera-0.frames") && b.contains("vision.cam3 <- sim-camera-3.frames");
        });
    }

    Path monitorJar;

    void debugMonitor() throws Exception {
        long id = rt.installAndStart(monitorJar);
        rt.awaitState("ACTIVE", T, "debug-monitor");
        try (CellPorts.State m1 = new CellPorts.State(rt.segment("debug-monitor", "m1_last"), CellPorts.SAMPLE)) {
            rt.waitUntil("the monitor showing tcp-correction's correction", T, () -> CellPorts.Sample.of(m1.read()) != null);
        }
        assertEquals("", rt.cmd("uninstall " + id));
        gone("debug-monitor");
        rt.waitUntil("debug-monitor's ports gone", T, () -> !Files.exists(rt.segment("debug-monitor", "m1_last")));
    }

    void parameter() {
        gain = gain == 2 ? 3 : 2;
        String r = rt.cmd("arflex:set sample-scaler gain " + gain);
        assertTrue(r.startsWith("sample-scaler.gain = "), r);
    }

    // ---- the run -------------------------------------------------------------------------------

    @Test
    void overrunsDuringStructuralChangesAgainstAControlRun() throws Exception {
        long windowNs = Long.getLong("arflex.bench.seconds", 30) * 1_000_000_000L;
        int rounds = Integer.getInteger("arflex.bench.rounds", 3);
        List<String> notes = new ArrayList<>();
        Map<String, Tally> control = new LinkedHashMap<>();
        Map<String, Tally> change = new LinkedHashMap<>();
        List<Map<String, Tally>> perWindow = new ArrayList<>();
        Map<String, List<Double>> eventMs = new LinkedHashMap<>();
        Map<String, Tally> byEvent = new LinkedHashMap<>();
        int resets = 0;
        // As the main job runs: the RT halves lock their memory (the tests' runtimes skip it).
        String mlock = System.setProperty("arflex.it.mlock", "true");
        Runtime started;
        try {
            started = new Runtime("cell-bench");
        } finally {
            if (mlock == null) {
                System.clearProperty("arflex.it.mlock");
            } else {
                System.setProperty("arflex.it.mlock", mlock);
            }
        }
        try (Runtime r = started) {
            rt = r;
            notes.add("RT halves with mlockall, as in the main job");
            notes.add(rt.renice(-10));
            CellRig.Gosh gosh = CellRig.cellGosh(rt);
            for (Path jar : gosh.starts()) {
                long id = rt.installAndStart(jar);
                String f = jar.getFileName().toString();
                bundles.put(f.equals("org.arflex.sim.camera.jar") ? "cameras"
                        : f.equals("org.arflex.cell.tool.gripper.jar") ? "tool-gripper" : f, id);
            }
            rt.awaitState("ACTIVE", T, CellE2EIT.CELL.toArray(new String[0]));
            for (String s : gosh.settings()) {
                String[] w = s.split("\\s+");
                assertTrue(rt.cmd(s).startsWith(w[1] + "." + w[2] + " = "), s);
            }
            assertEquals("trajectory.loop = true", rt.cmd("arflex:set trajectory loop true"));
            monitorJar = rt.dir.resolve("debug-monitor-tcp.jar");
            Jars.withContract(Components.jar("debug-monitor"), monitorJar,
                    c -> c.replace("<bind component=\"sample-counter\" port=\"count\"/>",
                            "<bind component=\"tcp-correction\" port=\"error\"/>")
                            .replace("<bind component=\"sample-scaler\" port=\"y\"/>",
                                    "<bind component=\"tcp-correction\" port=\"correction\"/>"));
            Map<String, Long> period = periods();
            // The operator's start-up check (a component that lost the heartbeat while the cell
            // came up waits for a reset), then the first window.
            resets += operator();

            Thread poller = new Thread(() -> {
                while (!Thread.currentThread().isInterrupted()) {
                    try {
                        for (Map<String, Object> i : Runtime.list(rt.dto(), "instances")) {
                            if (Boolean.TRUE.equals(i.get("safeMode")) || Boolean.TRUE.equals(i.get("awaitingReset"))) {
                                safeSeen.add((String) i.get("name"));
                            }
                        }
                    } catch (RuntimeException e) {
                        return; // the runtime is going away
                    }
                    LockSupport.parkNanos(500_000_000L); // the poller's rate (2 Hz), not a wait for a condition
                }
            }, "bench-dto-poller");
            poller.setDaemon(true);
            poller.start();
            try {
                for (int round = 0; round < rounds; round++) {
                    for (boolean changing : new boolean[] {false, true}) {
                        safeSeen.clear();
                        Map<String, Snap> a = snapshot();
                        long t0 = System.nanoTime();
                        if (changing) {
                            // Until the window's length has passed and the cell is whole again (a
                            // tool mounted, the cameras back); the next window goes on with the
                            // next change in turn.
                            while (System.nanoTime() - t0 < windowNs || CHANGES[next % CHANGES.length].equals("tool mounted")
                                    || CHANGES[next % CHANGES.length].equals("cameras back")) {
                                String what = CHANGES[next++ % CHANGES.length];
                                Map<String, Snap> e0 = snapshot();
                                switch (what) {
                                    case "tool unmounted" -> toolOff();
                                    case "tool mounted" -> toolOn();
                                    case "cameras removed" -> camerasOff();
                                    case "cameras back" -> camerasOn();
                                    case "debug monitor" -> debugMonitor();
                                    default -> parameter();
                                }
                                Map<String, Snap> e1 = snapshot();
                                eventMs.computeIfAbsent(what, x -> new ArrayList<>())
                                        .add((e1.get(MEASURED[0]).tNs() - e0.get(MEASURED[0]).tNs()) / 1e6);
                                Tally et = byEvent.computeIfAbsent(what, x -> new Tally());
                                for (String n : MEASURED) {
                                    Tally one = new Tally();
                                    one.add(e0.get(n), e1.get(n), period.get(n), false);
                                    et.addAll(one);
                                }
                            }
                        } else {
                            while (System.nanoTime() - t0 < windowNs) {
                                LockSupport.parkNanos(100_000_000L); // the control window: nothing happens
                            }
                        }
                        Map<String, Snap> b = snapshot();
                        Map<String, Tally> w = new LinkedHashMap<>();
                        for (String n : MEASURED) {
                            Tally t = new Tally();
                            t.add(a.get(n), b.get(n), period.get(n), safeSeen.contains(n));
                            w.put(n, t);
                            (changing ? change : control).computeIfAbsent(n, x -> new Tally()).addAll(t);
                        }
                        perWindow.add(w);
                        System.out.printf(Locale.ROOT, "[cell bench] round %d %s window: %.1f s%n", round + 1,
                                changing ? "change" : "control", (b.get(MEASURED[0]).tNs() - a.get(MEASURED[0]).tNs()) / 1e9);
                        resets += operator(); // between windows, not inside them
                    }
                }
            } finally {
                poller.interrupt();
                poller.join(10_000);
            }
            for (String name : new ArrayList<>(bundles.keySet())) {
                rt.cmd("uninstall " + bundles.get(name));
            }
        }
        notes.add("operator resets between windows: " + resets);
        report(windowNs, rounds, control, change, perWindow, eventMs, byEvent, notes);
    }

    /** Resets whatever waits for an operator's reset; returns how many. */
    int operator() {
        int n = 0;
        for (String name : CellRig.awaitingReset(rt)) {
            rt.cmd("arflex:reset " + name);
            n++;
        }
        return n;
    }

    void report(long windowNs, int rounds, Map<String, Tally> control, Map<String, Tally> change,
            List<Map<String, Tally>> perWindow, Map<String, List<Double>> eventMs, Map<String, Tally> byEvent,
            List<String> notes) throws Exception {
        StringBuilder out = new StringBuilder();
        out.append(String.format(Locale.ROOT, "Cell under structural change: %d rounds of a %d s control window and a %d s"
                + " change window%n", rounds, windowNs / 1_000_000_000L, windowNs / 1_000_000_000L));
        out.append("changes made (count, mean / max ms each):");
        eventMs.forEach((k, v) -> out.append(String.format(Locale.ROOT, "  %s %d (%.0f / %.0f)", k, v.size(),
                v.stream().mapToDouble(Double::doubleValue).average().orElse(0),
                v.stream().mapToDouble(Double::doubleValue).max().orElse(0))));
        out.append(String.format("%n%n"));
        String cols = String.format(Locale.ROOT, "%9s %7s %6s %5s %8s %8s", "cycles", "missed", "ovr", "wcet", "p99 us",
                "max us");
        String fmt = "%-15s | %-" + cols.length() + "s | %-" + cols.length() + "s | %s%n";
        out.append(String.format(Locale.ROOT, fmt, "", "control (no change)", "change", "extra"));
        out.append(String.format(Locale.ROOT, fmt, "component", cols, cols, "overruns"));
        for (String n : MEASURED) {
            Tally a = control.get(n);
            Tally b = change.get(n);
            out.append(String.format(Locale.ROOT, "%-15s | %s | %s | %+d%s%n", n, row(a), row(b), b.overruns - a.overruns,
                    a.restarts + b.restarts + a.safe + b.safe > 0 ? String.format("  (restarts %d/%d, windows in safe mode %d/%d)",
                            a.restarts, b.restarts, a.safe, b.safe) : ""));
        }
        out.append(String.format(Locale.ROOT, "%nper change, summed over its occurrences and the %d components above:%n",
                MEASURED.length));
        out.append(String.format(Locale.ROOT, "%-16s %6s %9s %6s %5s %8s%n", "change", "count", "cycles", "ovr", "wcet",
                "ms each"));
        byEvent.forEach((k, t) -> out.append(String.format(Locale.ROOT, "%-16s %6d %9d %6d %5d %8.0f%n", k,
                eventMs.get(k).size(), t.cycles, t.overruns, t.wcet,
                eventMs.get(k).stream().mapToDouble(Double::doubleValue).average().orElse(0))));
        out.append("missed = periods that passed minus cycles completed (+-1 per component and window: the DTO is"
                + " read in ~10 ms);\novr = deadline overruns; wcet = cycles over the"
                + " declared WCET;\np99/max = wake-up latency from the control block's histogram (upper bin edge; >200 = past"
                + " its range of 2000 bins of 100 ns).\n");
        notes.forEach(s -> out.append(s).append('\n'));
        System.out.print(out);

        StringBuilder json = new StringBuilder();
        json.append(String.format(Locale.ROOT, "{\"window_s\":%d,\"rounds\":%d,\"kernel\":\"%s\",\"events_ms\":{",
                windowNs / 1_000_000_000L, rounds, kernel()));
        json.append(String.join(",", eventMs.entrySet().stream().map(e -> "\"" + e.getKey() + "\":"
                + e.getValue().stream().map(d -> String.format(Locale.ROOT, "%.1f", d)).toList()).toList()));
        json.append("},\"control\":").append(tallies(control)).append(",\"change\":").append(tallies(change))
                .append(",\"by_change\":").append(tallies(byEvent));
        json.append(",\"windows\":[");
        for (int i = 0; i < perWindow.size(); i++) {
            json.append(i > 0 ? "," : "").append("{\"kind\":\"").append(i % 2 == 0 ? "control" : "change")
                    .append("\",\"components\":").append(tallies(perWindow.get(i))).append('}');
        }
        json.append("],\"notes\":[").append(String.join(",", notes.stream().map(s -> "\"" + s.replace("\"", "'") + "\"")
                .toList())).append("]}\n");
        Path file = Path.of(System.getProperty("arflex.root", ".")).resolve("target/bench/cell.json");
        Files.createDirectories(file.getParent());
        Files.writeString(file, json, StandardCharsets.UTF_8);
        System.out.println("wrote " + file);
    }

    static String row(Tally t) {
        return String.format(Locale.ROOT, "%9d %7d %6d %5d %8s %8s", t.cycles, t.periods - t.cycles,
                t.overruns, t.wcet, us(t.quantileUs(0.99), t), us(t.maxUs(), t));
    }

    static String us(double d, Tally t) {
        return Double.isNaN(d) ? "-" : Double.isInfinite(d) ? ">" + t.binNs * HIST_BINS / 1000
                : String.format(Locale.ROOT, "%.0f", d);
    }

    /** Bins of the control block's latency histogram below its overflow bin (rt-core control.h). */
    static final int HIST_BINS = 2000;

    static String tallies(Map<String, Tally> m) {
        return "{" + String.join(",", m.entrySet().stream().map(e -> "\"" + e.getKey() + "\":" + e.getValue().json()).toList())
                + "}";
    }

    static String kernel() {
        try {
            return Files.readString(Path.of("/proc/version")).strip().replace("\"", "'").replace("\\", "/");
        } catch (java.io.IOException e) {
            return "unknown";
        }
    }
}
