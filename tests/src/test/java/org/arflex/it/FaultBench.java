package org.arflex.it;


import java.nio.file.DirectoryStream;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Locale;
import java.util.Map;
import java.util.Random;
import org.junit.jupiter.api.Test;

/**
 * The fault benchmark ({@code ./arflex bench faults [--quick]}, issue 15): faults injected from
 * outside into a running cell whose arm moves (a looping program), each scenario N times, with a
 * seed that orders the rounds. Per scenario: pass/fail, time to safe (the arm's joint speeds
 * all under {@link FailSafeIT#STILL}, or every RT half flagged SUPERVISOR_LOST for the JVM
 * kill), time back to ACTIVE, and leaks. Prints a table, writes target/bench/faults.json, and
 * ends with {@code faults: P/T scenarios pass, leaks L}. Not a test: run by the script only
 * (failsafe runs *IT classes).
 *
 * <ul>
 * <li>S1 kill -9 of a provider (force-guard) and of the motion component (trajectory);</li>
 * <li>S3 SIGSTOP of the guard (stale safety input, then the DRCR's hang handling);</li>
 * <li>S5 the motion component (trajectory) killed each time it is back, until FAILED;</li>
 * <li>S15 the guard's output segment header overwritten while it runs (the robot holds on the
 * damaged header; the DRCR restarts the guard with a new segment);</li>
 * <li>S16 a 400 N push above the guard's limit;</li>
 * <li>S17 after every reset: no motion for 1000 robot cycles until the fresh command;</li>
 * <li>G the guard lost for good (killed until FAILED);</li>
 * <li>S18 kill -9 of the JVM ({@code --jvm-kills N} times): every RT half safe, then gone with its
 * objects.</li>
 * </ul>
 */
class FaultBench {

    /** One run; detectMs is from the fault to the DRCR's log line about it (-1: not measured). */
    record Run(boolean pass, double safeMs, double backMs, String note, double detectMs) {
        Run(boolean pass, double safeMs, double backMs, String note) {
            this(pass, safeMs, backMs, note, -1);
        }
    }

    /**
     * Milliseconds from {@code at} to the first DRCR log line after {@code mark} that contains
     * {@code text} (the log's time of day, same clock); -1 when none comes within 10 s.
     */
    static double detection(Runtime rt, int mark, java.time.LocalTime at, String text) {
        String[] line = {null};
        try {
            rt.waitUntil("the DRCR's line '" + text + "'", 10_000, () -> {
                line[0] = rt.logSince(mark).stream().filter(l -> l.contains(text)).findFirst().orElse(null);
                return line[0] != null;
            });
        } catch (AssertionError e) {
            return -1;
        }
        String[] w = line[0].replace("err| ", "").split(" ", 2);
        try {
            return java.time.Duration.between(at, java.time.LocalTime.parse(w[0])).toNanos() / 1e6;
        } catch (java.time.format.DateTimeParseException e) {
            return -1;
        }
    }

    private final Map<String, List<Run>> runs = new LinkedHashMap<>();
    private int s17Pass;
    private int s17Total;

    private void record(String scenario, Run r) {
        runs.computeIfAbsent(scenario, k -> new ArrayList<>()).add(r);
        System.out.printf(Locale.ROOT, "faults: %-12s %s safe %.0f ms, back %.0f ms %s%n", scenario, r.pass ? "pass" : "FAIL",
                r.safeMs, r.backMs, r.note);
    }

    /** Waits for the arm to stand still after the fault; robot ms to the first still value, or -1 after the deadline. */
    private static double timeToStill(Runtime rt, CellRig.Trace<CellRig.JointState> js) {
        int mark = js.size();
        try {
            rt.waitUntil("the arm still", 20_000, () -> js.size() > mark + 50 && FailSafeIT.stillFor(js, 50));
        } catch (AssertionError e) {
            return -1;
        }
        return FailSafeIT.stillAfterMs(js, mark);
    }

    /** S17: after the reset(s), 1000 robot cycles without motion; then the fresh command moves it. */
    private boolean resetThenCommand(Runtime rt, CellRig.Trace<CellRig.JointState> js) {
        try {
            rt.waitUntil("nothing awaits a reset", 30_000, () -> {
                if (!CellRig.awaitingReset(rt).isEmpty() || "FAILED".equals(rt.state("force-guard"))
                        || "FAILED".equals(rt.state("trajectory"))) {
                    rt.cmd("arflex:reset --cell");
                }
                return CellRig.awaitingReset(rt).isEmpty() && "ACTIVE".equals(rt.state("force-guard"))
                        && "ACTIVE".equals(rt.state("trajectory"));
            });
            int mark = js.size();
            rt.waitUntil("1000 robot cycles after the reset", 30_000, () -> js.size() > mark + 1000);
            boolean still = js.since(mark).stream().allMatch(j -> j.maxSpeed() <= FailSafeIT.STILL);
            s17Total++;
            if (still) {
                s17Pass++;
            }
            CellRig.set(rt, "trajectory", "run", "true");
            rt.waitUntil("moving after the fresh command", 30_000, () -> FailSafeIT.moving(js));
            return still;
        } catch (AssertionError e) {
            System.out.println("faults: reset/command failed: " + e.getMessage().lines().findFirst().orElse(""));
            return false;
        }
    }

    /**
     * Kills {@code name} each time it is back until it is FAILED; the arm must stop at the first
     * kill, stay still for 2000 robot cycles at the end, and move again only after the reset and
     * the fresh command.
     */
    private Run crashUntilFailed(Runtime rt, CellRig.Trace<CellRig.JointState> js, String name) throws Exception {
        long t0 = System.nanoTime();
        double safe = -1;
        for (int k = 0; k < 6 && !"FAILED".equals(rt.state(name)); k++) {
            long pid = rt.pid(name);
            if (pid == 0) {
                break;
            }
            FailSafeIT.kill9(pid);
            if (k == 0) {
                safe = timeToStill(rt, js);
            }
            try {
                rt.waitUntil(name + " back or FAILED", 30_000,
                        () -> rt.activeWithNewPid(name, pid) || "FAILED".equals(rt.state(name)));
            } catch (AssertionError e) {
                break;
            }
        }
        int mark = js.size();
        rt.waitUntil("2000 robot cycles with " + name + " lost", 30_000, () -> js.size() > mark + 2000);
        boolean stayed = js.since(mark).stream().allMatch(j -> j.maxSpeed() <= FailSafeIT.STILL);
        boolean failed = "FAILED".equals(rt.state(name));
        boolean ok = resetThenCommand(rt, js);
        return new Run(safe >= 0 && stayed && failed && ok, safe, 0,
                (failed ? "(" + name + " FAILED" : "(" + name + " not FAILED") + (stayed ? ", arm still)" : ", arm MOVED)"));
    }

    private static double backToActive(Runtime rt, String name, long oldPid, long t0) {
        try {
            rt.waitUntil(name + " back", 30_000, () -> rt.activeWithNewPid(name, oldPid));
            return (System.nanoTime() - t0) / 1e6;
        } catch (AssertionError e) {
            return -1;
        }
    }

    /**
     * Waits until {@code name} has at least two restarts left in its window (3 in 10 s for the
     * cell's components), so that a fault injected now restarts it instead of exhausting its
     * budget because of the scenario before (FAILED is right then, but it is another scenario).
     */
    private static void awaitRestartBudget(Runtime rt, String name) {
        rt.waitUntil(name + " with restarts left", 30_000, () -> {
            Object left = rt.instance(name).get("restartsLeft");
            return left instanceof Number n && n.intValue() >= 2;
        });
    }

    @Test
    void faults() throws Exception {
        int rounds = Integer.getInteger("arflex.bench.rounds", 3);
        long seed = Long.getLong("arflex.bench.seed", System.nanoTime());
        Random rnd = new Random(seed);
        System.out.println("faults: seed " + seed + ", rounds " + rounds);
        int leaks = 0;
        String rid;
        try (Runtime rt = new Runtime("faults")) {
            rid = rt.rid;
            FailSafeIT.movingCell(rt);
            CellRig.Trace<CellRig.JointState> js = new CellRig.Trace<>();
            try (CellRig.Port jp = new CellRig.Port(rt.segment("sim-robot", "joint_state"), CellRig.JOINT_STATE_SIZE);
                    CellRig.Recorder rec = new CellRig.Recorder()) {
                rec.add(jp, CellRig.JointState::of, CellRig.JointState::seq, js::add);
                rec.start();
                rt.waitUntil("the arm moving", 60_000, () -> FailSafeIT.moving(js));
                List<String> order = new ArrayList<>();
                for (int i = 0; i < rounds; i++) {
                    order.addAll(List.of("S1-guard", "S1-motion", "S3-guard", "S16-push", "S15-header"));
                }
                java.util.Collections.shuffle(order, rnd);
                for (String s : order) {
                    if (!s.startsWith("S16")) { // before the clock starts
                        awaitRestartBudget(rt, s.equals("S1-motion") ? "trajectory" : "force-guard");
                        awaitRestartBudget(rt, "trajectory");
                    }
                    rt.waitUntil("the arm moving", 30_000, () -> FailSafeIT.moving(js));
                    long t0 = System.nanoTime();
                    switch (s) {
                        case "S1-guard", "S1-motion" -> {
                            String name = s.equals("S1-guard") ? "force-guard" : "trajectory";
                            long pid = rt.pid(name);
                            int mark = rt.logMark();
                            java.time.LocalTime at = java.time.LocalTime.now();
                            FailSafeIT.kill9(pid);
                            double safe = timeToStill(rt, js);
                            double detect = detection(rt, mark, at, name + " (pid " + pid + ") ");
                            double back = backToActive(rt, name, pid, t0);
                            boolean ok = resetThenCommand(rt, js);
                            record(s, new Run(safe >= 0 && back >= 0 && ok, safe, back, "", detect));
                        }
                        case "S15-header" -> {
                            // bytes written into the guard's output segment: its header's magic
                            long pid = rt.pid("force-guard");
                            int mark = rt.logMark();
                            java.time.LocalTime at = java.time.LocalTime.now();
                            try (java.nio.channels.FileChannel ch = java.nio.channels.FileChannel.open(
                                    rt.segment("force-guard", "safety"), java.nio.file.StandardOpenOption.WRITE)) {
                                ch.write(java.nio.ByteBuffer.allocate(8), 0);
                            }
                            double safe = timeToStill(rt, js);
                            double detect = detection(rt, mark, at, "output force-guard.safety damaged while running");
                            double back = backToActive(rt, "force-guard", pid, t0);
                            boolean ok = resetThenCommand(rt, js);
                            record(s, new Run(safe >= 0 && back >= 0 && ok, safe, back, "(guard restarted, new segment)",
                                    detect));
                        }
                        case "S3-guard" -> {
                            long pid = rt.pid("force-guard");
                            Signals.tryToSend(pid, "STOP");
                            double safe = timeToStill(rt, js);
                            double back = backToActive(rt, "force-guard", pid, t0);
                            Signals.tryToSend(pid, "CONT"); // if the DRCR did not kill it, it goes on
                            boolean ok = resetThenCommand(rt, js);
                            record(s, new Run(safe >= 0 && back >= 0 && ok, safe, back, "(hang detection restarts it)"));
                        }
                        default -> {
                            CellRig.set(rt, "sim-robot", "push_duration_ms", "200");
                            CellRig.set(rt, "sim-robot", "push_force_n", "400");
                            double safe = timeToStill(rt, js);
                            // the operator resets once the contact is over: the push (200 ms of
                            // simulated time) has ended and the arm is at rest again
                            rt.waitUntil("the push over", 30_000, () -> System.nanoTime() - t0 > 400_000_000L);
                            CellRig.set(rt, "sim-robot", "push_force_n", "0");
                            int settled = js.size();
                            rt.waitUntil("the arm at rest after the push", 30_000,
                                    () -> js.size() > settled + 50 && FailSafeIT.stillFor(js, 200));
                            boolean ok = resetThenCommand(rt, js);
                            record(s, new Run(safe >= 0 && ok, safe, 0, ""));
                        }
                    }
                }
                // G: the guard lost for good (killed until FAILED), the arm stays stopped.
                record("G-guard-lost", crashUntilFailed(rt, js, "force-guard"));
                // S5: the motion component in a crash loop (killed each time it is back) until FAILED.
                awaitRestartBudget(rt, "trajectory");
                rt.waitUntil("the arm moving", 30_000, () -> FailSafeIT.moving(js));
                record("S5-crash-loop", crashUntilFailed(rt, js, "trajectory"));
                rec.close();
            }
        }
        leaks += leftovers(rid, "faults");

        // S18: kill -9 of the JVM, each time a fresh runtime with the moving cell.
        for (int i = 0; i < Integer.getInteger("arflex.bench.jvmkills", Math.max(1, rounds / 2)); i++) {
            String r18;
            double safeMs = -1;
            boolean gone = false;
            try (Runtime rt = new Runtime("faults-jvm")) {
                r18 = rt.rid;
                FailSafeIT.movingCell(rt);
                List<Path> ctls = ctlFiles(r18);
                long t0 = System.nanoTime();
                rt.crash();
                // polled every millisecond (not the 50 ms of waitUntil): the time is the figure
                long deadline = t0 + 10_000_000_000L;
                while (!ctls.stream().allMatch(p -> {
                    int f = CellPorts.ctlFlags(p);
                    return (f & CellPorts.FLAG_SUPERVISOR_LOST) != 0 && (f & CellPorts.FLAG_SAFE_ACTIVE) != 0;
                }) && System.nanoTime() < deadline) {
                    java.util.concurrent.locks.LockSupport.parkNanos(1_000_000L);
                }
                if (System.nanoTime() < deadline) {
                    safeMs = (System.nanoTime() - t0) / 1e6;
                } else {
                    System.out.println("faults: S18 not every RT half flagged SUPERVISOR_LOST and safe within 10 s");
                }
                try {
                    rt.waitUntil("the orphans gone with their objects", 30_000,
                            () -> Runtime.rtProcesses(r18).isEmpty() && rt.shmObjects().isEmpty());
                    gone = true;
                } catch (AssertionError e) {
                    System.out.println("faults: S18 " + e.getMessage().lines().findFirst().orElse(""));
                }
            }
            int l = leftovers(r18, "faults");
            leaks += l;
            record("S18-jvm-kill", new Run(safeMs >= 0 && gone && l == 0, safeMs, 0, ctlNote(l)));
        }
        report(seed, leaks);
    }

    private static String ctlNote(int leaks) {
        return leaks == 0 ? "" : "(" + leaks + " left)";
    }

    private static List<Path> ctlFiles(String rid) throws Exception {
        List<Path> l = new ArrayList<>();
        try (DirectoryStream<Path> ds = Files.newDirectoryStream(Path.of("/dev/shm"), "arflex." + rid + ".*.ctl")) {
            ds.forEach(l::add);
        }
        return l;
    }

    /** /dev/shm and /dev/mqueue objects and processes of a runtime id left after it closed. */
    /** RT processes and /dev/shm, /dev/mqueue objects left by runtime {@code rid}, each printed. */
    static int leftovers(String rid, String bench) throws Exception {
        int n = Runtime.rtProcesses(rid).size();
        for (String dir : new String[] {"/dev/shm", "/dev/mqueue"}) {
            if (Files.isDirectory(Path.of(dir))) {
                try (DirectoryStream<Path> ds = Files.newDirectoryStream(Path.of(dir), "arflex." + rid + ".*")) {
                    for (Path p : ds) {
                        System.out.println(bench + ": leak " + p);
                        n++;
                    }
                }
            }
        }
        return n;
    }

    private static String ms(double v) {
        return Double.isNaN(v) ? "-" : String.format(Locale.ROOT, "%.0f", v);
    }

    private static String ms1(double v) {
        return Double.isNaN(v) ? "-" : String.format(Locale.ROOT, "%.1f", v);
    }

    private static double pct(List<Double> v, double p) {
        if (v.isEmpty()) {
            return Double.NaN;
        }
        List<Double> s = new ArrayList<>(v);
        java.util.Collections.sort(s);
        return s.get(Math.min(s.size() - 1, (int) Math.ceil(p / 100 * s.size()) - 1));
    }

    private void report(long seed, int leaks) throws Exception {
        StringBuilder json = new StringBuilder(String.format(Locale.ROOT, "{\"seed\":%d,\"scenarios\":{", seed));
        System.out.printf(Locale.ROOT, "%n%-14s %5s %5s  %28s  %20s  %26s%n", "scenario", "runs", "pass",
                "time to safe p50/p99/max ms", "back to ACTIVE p50/max", "detection p50/p99/max ms");
        int pass = 0;
        int total = 0;
        boolean firstJ = true;
        for (var e : runs.entrySet()) {
            List<Run> rs = e.getValue();
            List<Double> safe = rs.stream().map(Run::safeMs).filter(x -> x >= 0).toList();
            List<Double> back = rs.stream().map(Run::backMs).filter(x -> x > 0).toList();
            List<Double> det = rs.stream().map(Run::detectMs).filter(x -> x >= 0).toList();
            long ok = rs.stream().filter(Run::pass).count();
            boolean all = ok == rs.size();
            total++;
            pass += all ? 1 : 0;
            System.out.printf(Locale.ROOT, "%-14s %5d %5d  %8s %8s %8s    %8s %8s      %6s %6s %6s%n", e.getKey(), rs.size(),
                    ok, ms(pct(safe, 50)), ms(pct(safe, 99)), ms(pct(safe, 100)), ms(pct(back, 50)), ms(pct(back, 100)),
                    ms1(pct(det, 50)), ms1(pct(det, 99)), ms1(pct(det, 100)));
            json.append(firstJ ? "" : ",").append(String.format(Locale.ROOT,
                    "\"%s\":{\"runs\":%d,\"pass\":%d,\"safe_ms\":{\"p50\":%.1f,\"p99\":%.1f,\"max\":%.1f},"
                            + "\"back_ms\":{\"p50\":%.1f,\"max\":%.1f},\"detect_ms\":{\"p50\":%.2f,\"p99\":%.2f,\"max\":%.2f}}",
                    e.getKey(), rs.size(), ok, pct(safe, 50), pct(safe, 99), pct(safe, 100), pct(back, 50), pct(back, 100),
                    pct(det, 50), pct(det, 99), pct(det, 100))
                    .replace("NaN", "null"));
            firstJ = false;
        }
        total++;
        boolean s17 = s17Total > 0 && s17Pass == s17Total;
        pass += s17 ? 1 : 0;
        System.out.printf(Locale.ROOT, "%-14s %5d %5d  (no motion for 1000 robot cycles after each reset, until the command)%n",
                "S17-no-resume", s17Total, s17Pass);
        json.append(String.format(Locale.ROOT, ",\"S17-no-resume\":{\"runs\":%d,\"pass\":%d}},\"leaks\":%d,\"pass\":%d,\"total\":%d}%n",
                s17Total, s17Pass, leaks, pass, total));
        Path out = Path.of(System.getProperty("arflex.bench.out", "target/bench/faults.json"));
        Files.createDirectories(out.toAbsolutePath().getParent());
        Files.writeString(out, json);
        System.out.println("JSON: " + out.toAbsolutePath());
        System.out.println("faults: " + pass + "/" + total + " scenarios pass, leaks " + leaks);
    }
}
