package org.arflex.it;

import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.Collections;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Locale;
import java.util.Map;
import java.util.concurrent.locks.LockSupport;

/**
 * Benchmark (not a test): times of the DRCR's own work on the real runtime, measured from the
 * outside through the ports, N rounds in one runtime. Prints a table and writes JSON.
 *
 * <ul>
 * <li>install-to-first-cycle: Gogo {@code start} of the counter bundle, installed and prepared
 * (resolved, its executable extracted; D54), sent -> first sample on its port (includes the Gogo
 * round trip, the plan, shm/mq creation, the hash of the executable, spawn, READY, START and the
 * first cycle, which runs at START);</li>
 * <li>install-and-start-to-first-cycle: Gogo {@code install} sent, then {@code start} at once ->
 * first sample: the same with the contract read, Felix's resolution and the extraction on the
 * way (the preparation races the start);</li>
 * <li>crash-to-dependents-safe: SIGKILL of the counter -> the scaler's output shows its safe
 * value 0;</li>
 * <li>crash-to-active-again: SIGKILL of the counter -> the scaler's output carries a new
 * non-zero value again (restart backoff 100 ms included).</li>
 * </ul>
 *
 * Run: {@code mvn -pl tests -o -q test-compile exec:java -Dexec.classpathScope=test
 * -Dexec.mainClass=org.arflex.it.DrcrBench -Dexec.args="20"} with the system properties of the
 * integration tests (see tests/README.md).
 */
public final class DrcrBench {

    private DrcrBench() {
    }

    private static long spinUntil(long deadlineNs, Runtime.Cond c) throws Exception {
        while (System.nanoTime() < deadlineNs) {
            if (c.test()) {
                return System.nanoTime();
            }
            LockSupport.parkNanos(100_000);
        }
        throw new IllegalStateException("deadline passed");
    }

    public static void main(String[] args) throws Exception {
        int n = args.length > 0 ? Integer.parseInt(args[0]) : 20;
        List<Double> install = new ArrayList<>();
        List<Double> installStart = new ArrayList<>();
        List<Double> safe = new ArrayList<>();
        List<Double> back = new ArrayList<>();
        try (Runtime rt = new Runtime("bench")) {
            Path x = rt.segment("sample-counter", "count");
            Path y = rt.segment("sample-scaler", "y");
            long scalerBundle = rt.installAndStart(CellIT.SCALER);
            for (int i = 0; i < 2 * n; i++) {
                boolean prepared = i % 2 == 0; // the two ways, alternately, under the same conditions
                int mark = rt.logMark();
                long i0 = System.nanoTime();
                long id = rt.install(CellIT.COUNTER);
                if (prepared) {
                    String line = "bundle " + id + " (";
                    rt.waitUntil("bundle " + id + " prepared", 30_000, () -> rt.logSince(mark).stream()
                            .anyMatch(l -> l.contains(line) && l.contains("prepared for its start")));
                }
                long t0 = System.nanoTime();
                rt.cmd("start " + id);
                long t1 = spinUntil(t0 + 30_000_000_000L, () -> Files.exists(x) && Ports.readState(x) != null);
                if (prepared) {
                    install.add((t1 - t0) / 1e6);
                } else {
                    installStart.add((t1 - i0) / 1e6);
                }
                rt.awaitState("ACTIVE", 30_000, "sample-counter", "sample-scaler");
                spinUntil(System.nanoTime() + 30_000_000_000L, () -> {
                    Ports.Sample s = Ports.readState(y);
                    return s != null && s.value() != 0.0;
                });
                long pid = rt.pid("sample-counter");
                long k0 = System.nanoTime();
                ProcessHandle.of(pid).ifPresent(ProcessHandle::destroyForcibly);
                long k1 = spinUntil(k0 + 30_000_000_000L, () -> {
                    Ports.Sample s = Ports.readState(y);
                    return s != null && s.value() == 0.0;
                });
                safe.add((k1 - k0) / 1e6);
                long k2 = spinUntil(k0 + 30_000_000_000L, () -> {
                    Ports.Sample s = Ports.readState(y);
                    return s != null && s.value() != 0.0;
                });
                back.add((k2 - k0) / 1e6);
                rt.cmd("uninstall " + id);
                rt.waitUntil("counter gone", 30_000, () -> rt.instance("sample-counter") == null);
            }
            rt.cmd("uninstall " + scalerBundle);
        }
        Map<String, List<Double>> all = new LinkedHashMap<>();
        all.put("install_to_first_cycle_ms", install);
        all.put("install_and_start_to_first_cycle_ms", installStart);
        all.put("crash_to_dependents_safe_ms", safe);
        all.put("crash_to_active_again_ms", back);
        StringBuilder json = new StringBuilder("{\"rounds\":" + n);
        System.out.printf(Locale.ROOT, "%-36s %4s %8s %8s %8s %8s%n", "metric (ms)", "n", "min", "p50", "p95", "max");
        for (var e : all.entrySet()) {
            List<Double> v = new ArrayList<>(e.getValue());
            Collections.sort(v);
            double p50 = v.get((int) Math.floor(0.50 * (v.size() - 1)));
            double p95 = v.get((int) Math.floor(0.95 * (v.size() - 1)));
            System.out.printf(Locale.ROOT, "%-36s %4d %8.1f %8.1f %8.1f %8.1f%n", e.getKey(), v.size(), v.get(0), p50, p95,
                    v.get(v.size() - 1));
            json.append(String.format(Locale.ROOT, ",\"%s\":{\"n\":%d,\"min\":%.3f,\"p50\":%.3f,\"p95\":%.3f,\"max\":%.3f}",
                    e.getKey(), v.size(), v.get(0), p50, p95, v.get(v.size() - 1)));
        }
        json.append("}\n");
        Path out = Path.of(System.getProperty("arflex.it.work", "target/it")).getParent().resolve("bench-drcr.json");
        Files.createDirectories(out.getParent());
        Files.writeString(out, json);
        System.out.println("wrote " + out);
    }
}
