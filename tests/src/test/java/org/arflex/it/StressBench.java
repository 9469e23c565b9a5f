package org.arflex.it;


import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.Locale;
import java.util.Map;
import java.util.TreeMap;
import java.util.concurrent.TimeUnit;
import org.junit.jupiter.api.Test;

/**
 * No false stops from the machine (issue 15 finding 6): the moving cell, as the main job runs
 * it (mlockall, the JVM at nice -10), under {@code stress-ng} (CPU, memory, I/O and scheduler
 * load on every core) for {@code arflex.bench.minutes} minutes (10 by default). Counts safe stops
 * (safe-hook cycles, a latched reset, any HOLDING of the moving components that is not the
 * program's own), hang kills and restarts of the healthy components; the arm must keep moving.
 * A safe stop is a component that ran its safe hook, awaited a reset or held the arm at any time.
 * Afterwards, one real hang (SIGSTOP of the guard) must still be caught within its contract's
 * timeout. Prints a table, writes target/bench/stress.json, and ends with
 * {@code stress: S safe stops, K hang kills, R restarts in M min; hang caught in H ms}, then the
 * guard's force trips over the stressed run, each printed with its cause (TripWatch, D77):
 * {@code trips: N in S s under stress-ng}. Not a
 * test: run by the script only.
 */
class StressBench {

    private static final String[] CELL = {"sim-robot", "force-guard", "trajectory", "tcp-correction"};

    @Test
    void stress() throws Exception {
        double minutes = Double.parseDouble(System.getProperty("arflex.bench.minutes", "10"));
        System.setProperty("arflex.it.mlock", "true");
        List<String> notes = new ArrayList<>();
        try (Runtime rt = new Runtime("stress")) {
            notes.add(rt.renice(-10));
            FailSafeIT.movingCell(rt);
            CellRig.Trace<CellRig.JointState> js = new CellRig.Trace<>();
            Map<String, long[]> before = counters(rt);
            Map<String, Long> pids = new TreeMap<>();
            for (String c : CELL) {
                if (rt.instance(c) != null) {
                    pids.put(c, rt.pid(c));
                }
            }
            int mark = rt.logMark();
            int stillWindows = 0;
            int windows = 0;
            Map<String, Integer> holdingSeen = new TreeMap<>();
            java.util.Set<String> stopped = new java.util.TreeSet<>();
            int resetsSeen = 0;
            int trips = 0; // the guard's force trips (latched FORCE_LIMIT), each printed with its cause (D77)
            boolean tripped = false;
            try (CellRig.Port jp = new CellRig.Port(rt.segment("sim-robot", "joint_state"), CellRig.JOINT_STATE_SIZE);
                    CellRig.Recorder rec = new CellRig.Recorder(); TripWatch watch = TripWatch.open(rt)) {
                rec.add(jp, CellRig.JointState::of, CellRig.JointState::seq, js::add);
                rec.start();
                rt.waitUntil("the arm moving", 60_000, () -> FailSafeIT.moving(js));
                int cpus = java.lang.Runtime.getRuntime().availableProcessors();
                long seconds = Math.round(minutes * 60);
                Process stress = new ProcessBuilder("stress-ng", "--cpu", Integer.toString(cpus), "--vm", "1",
                        "--vm-bytes", "256M", "--io", "1", "--sched", "1", "--timeout", seconds + "s", "--quiet")
                        .redirectErrorStream(true).redirectOutput(ProcessBuilder.Redirect.DISCARD).start();
                long end = System.nanoTime() + TimeUnit.SECONDS.toNanos(seconds);
                try {
                    // One look per second: does the arm move, does anything hold or wait for a reset?
                    while (System.nanoTime() < end) {
                        int m = js.size();
                        long t = System.nanoTime();
                        rt.waitUntil("a second of the stressed cell", 10_000, () -> System.nanoTime() - t > 1_000_000_000L);
                        windows++;
                        if (js.since(m).stream().allMatch(j -> j.maxSpeed() <= FailSafeIT.STILL)) {
                            stillWindows++;
                        }
                        for (Map<String, Object> i : Runtime.list(rt.dto(), "instances")) {
                            Object h = i.get("holding");
                            if (h != null && !String.valueOf(h).startsWith("holds: waits for a reference")) {
                                holdingSeen.merge(i.get("name") + ": " + h, 1, Integer::sum);
                                stopped.add((String) i.get("name"));
                            }
                        }
                        List<String> awaiting = CellRig.awaitingReset(rt);
                        if (!awaiting.isEmpty()) {
                            resetsSeen++;
                            stopped.addAll(awaiting);
                        }
                        boolean latched = awaiting.contains("force-guard") && watch != null && watch.trip() != null;
                        if (latched && !tripped) {
                            trips++;
                            System.out.println("stress: trip after " + windows + " s under stress-ng: " + watch.explain(watch.trip())
                                    .replace("\n", "\nstress: "));
                        }
                        tripped = latched;
                    }
                } finally {
                    stress.destroy();
                    stress.waitFor(30, TimeUnit.SECONDS);
                }
            }
            Map<String, long[]> after = counters(rt);
            long safeCycles = 0;
            long restarts = 0;
            for (String c : after.keySet()) {
                long[] b = before.getOrDefault(c, new long[2]);
                safeCycles += after.get(c)[0] - b[0];
                if (after.get(c)[0] > b[0]) {
                    stopped.add(c);
                }
                Long pid = pids.get(c);
                restarts += pid != null && rt.instance(c) != null && rt.pid(c) != pid ? 1 : 0;
            }
            long hangKills = rt.logSince(mark).stream().filter(l -> l.contains(": hung: ")).count();
            int stops = stopped.size();

            // A real hang is still caught: SIGSTOP of the guard (heartbeat timeout of its contract).
            long pid = rt.pid("force-guard");
            int m2 = rt.logMark();
            java.time.LocalTime at = java.time.LocalTime.now();
            new ProcessBuilder("kill", "-STOP", Long.toString(pid)).start().waitFor();
            double caught = -1;
            try {
                rt.waitUntil("the hang caught", 30_000, () -> rt.logSince(m2).stream().anyMatch(l -> l.contains("force-guard: hung")));
                String line = rt.logSince(m2).stream().filter(l -> l.contains("force-guard: hung")).findFirst().orElseThrow();
                caught = java.time.Duration.between(at, java.time.LocalTime.parse(line.replace("err| ", "").split(" ", 2)[0]))
                        .toNanos() / 1e6;
            } catch (AssertionError e) {
                caught = -1;
            } finally {
                new ProcessBuilder("kill", "-CONT", Long.toString(pid)).start().waitFor();
            }

            System.out.printf(Locale.ROOT, "stress: %s%n", String.join("; ", notes));
            // why anything stopped, from the runtime's own log: its stalls and the halves' safe modes
            rt.logSince(mark).stream()
                    .filter(l -> !l.contains("g! ") && (l.contains("silent for") || l.contains("answered after")
                            || l.contains("safe mode") || l.contains("heartbeat") || l.contains("reset")
                            || l.contains("protective stop")))
                    .limit(40).forEach(l -> System.out.println("stress: log " + l));
            System.out.printf(Locale.ROOT, "stress: %-40s %d%n", "seconds under stress-ng", windows);
            System.out.printf(Locale.ROOT, "stress: %-40s %d%n", "seconds with the arm still", stillWindows);
            System.out.printf(Locale.ROOT, "stress: %-40s %d%n", "safe-hook cycles (all components)", safeCycles);
            System.out.printf(Locale.ROOT, "stress: %-40s %d%n", "seconds with a reset awaited", resetsSeen);
            System.out.printf(Locale.ROOT, "stress: %-40s %s%n", "HOLDING seen (seconds)", holdingSeen);
            System.out.printf(Locale.ROOT, "stress: %-40s %s%n", "components that stopped", stopped);
            System.out.printf(Locale.ROOT, "stress: %-40s %d%n", "hang kills", hangKills);
            System.out.printf(Locale.ROOT, "stress: %-40s %d%n", "restarts", restarts);
            System.out.printf(Locale.ROOT, "stress: %-40s %.0f ms (timeout %s)%n", "a real hang (SIGSTOP guard) caught after",
                    caught, "of its contract");
            Path out = Path.of(System.getProperty("arflex.bench.out", "target/bench/stress.json"));
            Files.createDirectories(out.toAbsolutePath().getParent());
            Files.writeString(out, String.format(Locale.ROOT, "{\"minutes\":%.1f,\"seconds\":%d,\"still_seconds\":%d,"
                    + "\"safe_cycles\":%d,\"reset_seconds\":%d,\"holding\":%d,\"hang_kills\":%d,\"restarts\":%d,"
                    + "\"hang_caught_ms\":%.1f}%n", minutes, windows, stillWindows, safeCycles, resetsSeen,
                    holdingSeen.values().stream().mapToInt(x -> x).sum(), hangKills, restarts, caught));
            System.out.println("JSON: " + out.toAbsolutePath());
            // the guard was stopped and killed: its restart is the DRCR's; the reset is the operator's
            rt.waitUntil("the guard back", 30_000, () -> rt.activeWithNewPid("force-guard", pid));
            System.out.printf(Locale.ROOT, "stress: %d safe stops, %d hang kills, %d restarts in %.0f min; hang caught in %.0f ms%n",
                    stops, hangKills, restarts, minutes, caught);
            System.out.printf(Locale.ROOT, "trips: %d in %d s under stress-ng%n", trips, windows);
        }
    }

    /** Per component: safe-hook cycles, update errors. */
    private static Map<String, long[]> counters(Runtime rt) {
        Map<String, long[]> m = new TreeMap<>();
        for (Map<String, Object> i : Runtime.list(rt.dto(), "instances")) {
            @SuppressWarnings("unchecked")
            Map<String, Object> s = (Map<String, Object>) i.get("stats");
            if (s != null) {
                m.put((String) i.get("name"), new long[] {((Number) s.get("safeCycles")).longValue(),
                    ((Number) s.get("updateErrors")).longValue()});
            }
        }
        return m;
    }
}
