package org.arflex.planner.bench;

import java.io.IOException;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.Arrays;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Locale;
import java.util.Map;
import java.util.Optional;
import java.util.Random;
import org.arflex.contract.Binding;
import org.arflex.contract.Contract;
import org.arflex.contract.FaultPolicy;
import org.arflex.contract.PortSpec;
import org.arflex.contract.Resources;
import org.arflex.contract.Timing;
import org.arflex.contract.TypeVersion;
import org.arflex.planner.AdmissionResult;
import org.arflex.planner.Capacities;
import org.arflex.planner.Change;
import org.arflex.planner.Planner;
import org.arflex.planner.impl.Admission;
import org.arflex.planner.impl.ResolveDelta;
import org.arflex.planner.impl.Resolver;

/**
 * Benchmark of the planner on synthetic cells of 100, 1,000 and 10,000 components (not a test).
 *
 * <p>Graph: chains of 20 components (each link reads the previous one) and, every tenth
 * component, a fan-in aggregator reading 4 to 8 earlier components; 12 shared port types
 * (versions 1.0 to 1.2, state/stream/frame), inputs bound explicitly (60%), by a filter on an
 * {@code id} attribute (30%) or by a unique port type without rule (10%), 5% optional. Timing:
 * 30% periodic, 10% sporadic, 60% service; periods 1 to 100 ms with rate-monotonic priorities,
 * 2% constrained deadlines (which force response-time analysis on their CPU); 16 CPUs.
 *
 * <p>Measures: full resolve (one batch), full admission, full plan ({@link Planner#apply} of
 * the install of everything) and incremental resolver changes (add a leaf consumer, remove it,
 * replace a middle component by a new version, remove a middle component and put it back),
 * plus an incremental {@link Planner#plan} of one install. Prints a table and writes JSON, with
 * wall-clock and thread CPU times (the latter is what the code costs when the machine is shared).
 *
 * <p>Run: {@code mvn -q -o -pl management/planner exec:java -Dexec.classpathScope=test
 * -Dexec.mainClass=org.arflex.planner.bench.PlannerBench [-Dexec.args=out.json]}.
 */
public final class PlannerBench {

    private static final String[] TYPES = {"arflex.JointState", "arflex.Pose", "arflex.Image", "arflex.Sample",
        "arflex.Wrench", "arflex.Trajectory", "arflex.Twist", "arflex.Correction", "arflex.Status",
        "arflex.PointCloud", "arflex.Io", "arflex.Gripper"};
    private static final long MS = 1_000_000L;
    private static final long[] PERIODS = {1 * MS, 2 * MS, 5 * MS, 10 * MS, 20 * MS, 50 * MS, 100 * MS};

    private PlannerBench() {
    }

    static PortSpec.Method methodOf(int type) {
        return type == 2 ? PortSpec.Method.FRAME : type == 9 ? PortSpec.Method.STREAM : PortSpec.Method.STATE;
    }

    static Contract component(int i, int n, Random rnd, String version) {
        String name = "c" + i;
        List<PortSpec> ports = new ArrayList<>();
        int type = i % TYPES.length;
        ports.add(new PortSpec("out", PortSpec.Direction.OUT, TYPES[type], new TypeVersion(1, 2), methodOf(type), 4,
                PortSpec.Overflow.DROP_OLDEST, Optional.empty(), false));
        ports.add(new PortSpec("u", PortSpec.Direction.OUT, "bench.U" + i, new TypeVersion(1, 0), PortSpec.Method.STATE,
                1, PortSpec.Overflow.DROP_OLDEST, Optional.empty(), false));
        List<Integer> providers = new ArrayList<>();
        if (i % 20 != 0) {
            providers.add(i - 1);
        }
        if (i % 10 == 9 && i > 20) {
            int k = 4 + rnd.nextInt(5);
            for (int j = 0; j < k; j++) {
                int p = rnd.nextInt(i - 1);
                if (!providers.contains(p)) {
                    providers.add(p);
                }
            }
        }
        int idx = 0;
        for (int p : providers) {
            int r = rnd.nextInt(10);
            int ptype = p % TYPES.length;
            Optional<Binding> b;
            String portType = TYPES[ptype];
            PortSpec.Method m = methodOf(ptype);
            TypeVersion v = new TypeVersion(1, rnd.nextInt(3));
            if (r < 6) {
                b = Optional.of(Binding.explicit("c" + p, "out"));
            } else if (r < 9) {
                b = Optional.of(Binding.filter("(id=c" + p + ")"));
            } else {
                b = Optional.empty();
                portType = "bench.U" + p;
                m = PortSpec.Method.STATE;
                v = new TypeVersion(1, 0);
            }
            ports.add(new PortSpec("in" + idx++, PortSpec.Direction.IN, portType, v, m, 4, PortSpec.Overflow.DROP_OLDEST,
                    b, rnd.nextInt(20) == 0));
        }
        int kind = rnd.nextInt(10);
        Contract.TaskType tt = kind < 3 ? Contract.TaskType.PERIODIC
                : kind < 4 ? Contract.TaskType.SPORADIC : Contract.TaskType.SERVICE;
        int pi = rnd.nextInt(PERIODS.length);
        long period = PERIODS[pi];
        long deadline = rnd.nextInt(50) == 0 ? period / 2 : period;
        // About 0.15% of a CPU each: 10,000 components put ~0.3 on each of 16 CPUs.
        long wcet = Math.max(1000, period * (5 + rnd.nextInt(20)) / 10_000);
        int prio = 90 - pi * 10;
        Timing timing = new Timing(period, deadline, wcet, prio, List.of());
        return new Contract(name, version, "", name + "-rt", tt, false, Map.of("id", name), ports, List.of(), timing,
                new Resources(1L << 20, 1000), 1 + rnd.nextInt(5),
                new FaultPolicy(FaultPolicy.Restart.PERMANENT, 3, 10_000, 100, FaultPolicy.SafeOutput.HOLD, 500),
                Optional.empty(), "bench");
    }

    static List<Contract> graph(int n, long seed) {
        Random rnd = new Random(seed);
        List<Contract> cs = new ArrayList<>(n);
        for (int i = 0; i < n; i++) {
            cs.add(component(i, n, rnd, "1.0.0"));
        }
        return cs;
    }

    static Capacities caps(int n) {
        return Capacities.of(16, 0.9, (long) n * 4 << 20, (long) n * 10_000);
    }

    private static final java.lang.management.ThreadMXBean THREADS = java.lang.management.ManagementFactory.getThreadMXBean();

    /** Wall and thread CPU time of one measured call, ns. */
    static long cpuNow() {
        return THREADS.getCurrentThreadCpuTime();
    }

    record Stats(double meanUs, double p50Us, double p99Us, double maxUs) {
        static Stats of(long[] ns) {
            long[] s = ns.clone();
            Arrays.sort(s);
            double sum = 0;
            for (long v : s) {
                sum += v;
            }
            return new Stats(sum / s.length / 1e3, s[s.length / 2] / 1e3, s[(int) Math.min(s.length - 1,
                    Math.ceil(s.length * 0.99) - 1)] / 1e3, s[s.length - 1] / 1e3);
        }
    }

    public static void main(String[] args) throws IOException {
        Path out = Path.of(args.length > 0 ? args[0] : "target/planner-bench.json");
        int[] sizes = {100, 1_000, 10_000};
        Map<String, Object> json = new LinkedHashMap<>();
        json.put("java", System.getProperty("java.version"));
        json.put("cpus", Runtime.getRuntime().availableProcessors());
        List<Map<String, Object>> rows = new ArrayList<>();
        // Warm-up: the whole procedure on the middle size, twice.
        for (int w = 0; w < 2; w++) {
            run(1_000, 3, 100, false);
        }
        double load = java.lang.management.ManagementFactory.getOperatingSystemMXBean().getSystemLoadAverage();
        json.put("loadAverageAtStart", load);
        System.out.printf(Locale.ROOT, "load average %.2f on %d cpus (wall times suffer from other load; cpu = thread CPU time)%n",
                load, Runtime.getRuntime().availableProcessors());
        System.out.printf(Locale.ROOT, "%-7s %-28s %10s %10s %10s %10s %10s%n", "n", "operation", "wall mean", "wall p50",
                "wall p99", "cpu p50", "cpu p99");
        for (int n : sizes) {
            int fullReps = n >= 10_000 ? 5 : 10;
            rows.addAll(run(n, fullReps, 300, true));
        }
        json.put("results", rows);
        Map<String, Object> last = rows.stream()
                .filter(r -> (int) r.get("n") == 10_000 && "plan one install (dry run)".equals(r.get("operation")))
                .findFirst().orElseThrow();
        json.put("dryRunInstall10000CpuP50Ms", (double) last.get("cpuP50Us") / 1000);
        json.put("dryRunInstall10000WallP50Ms", (double) last.get("p50Us") / 1000);
        Files.createDirectories(out.toAbsolutePath().getParent());
        Files.writeString(out, toJson(json));
        System.out.println("wrote " + out.toAbsolutePath());
        // Thread CPU time: what the code costs, whatever else the machine runs (the table has wall too).
        System.out.printf(Locale.ROOT, "planner: dry-run install at 10000 components p50 %.1f ms%n",
                (double) last.get("cpuP50Us") / 1000);
    }

    /** Wall-clock and thread CPU times of repeated measurements. */
    static final class Series {
        final long[] wall;
        final long[] cpu;
        int i;
        private long w0;
        private long c0;

        Series(int reps) {
            wall = new long[reps];
            cpu = new long[reps];
        }

        void start() {
            c0 = cpuNow();
            w0 = System.nanoTime();
        }

        void stop() {
            wall[i] = System.nanoTime() - w0;
            cpu[i] = cpuNow() - c0;
            i++;
        }

        static Series sum(Series a, Series b) {
            Series s = new Series(a.wall.length);
            for (int k = 0; k < a.wall.length; k++) {
                s.wall[k] = a.wall[k] + b.wall[k];
                s.cpu[k] = a.cpu[k] + b.cpu[k];
            }
            s.i = a.wall.length;
            return s;
        }
    }

    static List<Map<String, Object>> run(int n, int fullReps, int incReps, boolean print) {
        List<Contract> cs = graph(n, 7);
        Capacities caps = caps(n);
        List<Map<String, Object>> rows = new ArrayList<>();
        Series resolve = new Series(fullReps);
        Series admit = new Series(fullReps);
        Series plan = new Series(fullReps);
        Resolver r = null;
        AdmissionResult adm = null;
        for (int k = 0; k < fullReps; k++) {
            resolve.start();
            r = new Resolver();
            r.apply(cs, List.of());
            resolve.stop();
            admit.start();
            adm = Admission.admit(r, caps, Map.of());
            admit.stop();
            plan.start();
            Planner p = new Planner(caps);
            p.apply(Change.install(cs.toArray(new Contract[0])));
            plan.stop();
        }
        rows.add(row(n, "full resolve", resolve, Map.of("satisfied", r.satisfied().size(), "wires", r.wires().size())));
        rows.add(row(n, "full admission", admit, Map.of("admitted", adm.admitted().size(),
                "rtaCpus", adm.cpus().stream().filter(c -> c.test().startsWith("response")).count())));
        rows.add(row(n, "full resolve+admit", Series.sum(resolve, admit), Map.of()));
        rows.add(row(n, "full plan (Planner.apply)", plan, Map.of()));

        // Incremental resolver changes on the resolved cell.
        Random rnd = new Random(11);
        Series add = new Series(incReps);
        Series remove = new Series(incReps);
        Series replace = new Series(incReps);
        Series removeMid = new Series(incReps);
        Series putBack = new Series(incReps);
        long touchedAdd = 0;
        long touchedReplace = 0;
        long touchedRemoveMid = 0;
        long maxTouchedRemoveMid = 0;
        long maxDownRemoveMid = 0;
        for (int k = 0; k < incReps; k++) {
            Contract leaf = leaf("leaf" + k, rnd.nextInt(n));
            add.start();
            ResolveDelta d = r.put(leaf);
            add.stop();
            touchedAdd += d.touched();
            remove.start();
            r.remove(leaf.name());
            remove.stop();
            int mid = rnd.nextInt(n);
            Contract old = r.contract("c" + mid).get();
            Contract bumped = new Contract(old.name(), "1.0." + (k + 1), old.description(), old.executable(),
                    old.taskType(), old.movesHardware(), old.attributes(), old.ports(), old.properties(), old.timing(),
                    old.resources(), old.criticality(), old.fault(), old.update(), old.source());
            replace.start();
            d = r.put(bumped);
            replace.stop();
            touchedReplace += d.touched();
            removeMid.start();
            d = r.remove(bumped.name());
            removeMid.stop();
            touchedRemoveMid += d.touched();
            maxTouchedRemoveMid = Math.max(maxTouchedRemoveMid, d.touched());
            maxDownRemoveMid = Math.max(maxDownRemoveMid, d.becameUnsatisfied().size());
            putBack.start();
            r.put(old);
            putBack.stop();
        }
        rows.add(row(n, "add one (leaf)", add, Map.of("meanTouched", touchedAdd / (double) incReps)));
        rows.add(row(n, "remove one (leaf)", remove, Map.of()));
        rows.add(row(n, "replace one (middle)", replace, Map.of("meanTouched", touchedReplace / (double) incReps)));
        rows.add(row(n, "remove one (middle)", removeMid, Map.of("meanTouched", touchedRemoveMid / (double) incReps,
                "maxTouched", maxTouchedRemoveMid, "maxBecameUnsatisfied", maxDownRemoveMid)));
        rows.add(row(n, "put it back (middle)", putBack, Map.of()));

        // A whole plan of one change (dry run). The first plan after a commit computes the plan
        // of no change in full (once per state); the dry runs of one install derive from it.
        Planner p = new Planner(caps);
        p.apply(Change.install(cs.toArray(new Contract[0])));
        Series picture = new Series(1);
        picture.start();
        p.current();
        picture.stop();
        rows.add(row(n, "plan of no change (once)", picture, Map.of()));
        int planReps = n >= 10_000 ? 100 : 300;
        Series planOne = new Series(planReps);
        for (int k = 0; k < planReps; k++) {
            Contract leaf = leaf("leaf" + k, rnd.nextInt(n));
            planOne.start();
            p.plan(Change.install(leaf));
            planOne.stop();
        }
        rows.add(row(n, "plan one install (dry run)", planOne, Map.of()));
        if (print) {
            for (Map<String, Object> row : rows) {
                System.out.printf(Locale.ROOT, "%-7d %-28s %10s %10s %10s %10s %10s%n", n, row.get("operation"),
                        fmt((double) row.get("meanUs")), fmt((double) row.get("p50Us")), fmt((double) row.get("p99Us")),
                        fmt((double) row.get("cpuP50Us")), fmt((double) row.get("cpuP99Us")));
            }
        }
        return rows;
    }

    static Contract leaf(String name, int target) {
        int ptype = target % TYPES.length;
        PortSpec in = new PortSpec("in", PortSpec.Direction.IN, TYPES[ptype], new TypeVersion(1, 0), methodOf(ptype), 4,
                PortSpec.Overflow.DROP_OLDEST, Optional.of(Binding.explicit("c" + target, "out")), false);
        return new Contract(name, "1.0.0", "", name + "-rt", Contract.TaskType.PERIODIC, false, Map.of("id", name),
                List.of(in), List.of(), new Timing(10 * MS, 10 * MS, 10_000, 50, List.of()), new Resources(1L << 20, 0), 1,
                new FaultPolicy(FaultPolicy.Restart.PERMANENT, 3, 10_000, 100, FaultPolicy.SafeOutput.HOLD, 500),
                Optional.empty(), "bench");
    }

    static String fmt(double us) {
        return us >= 1000 ? String.format(Locale.ROOT, "%.1f ms", us / 1000) : String.format(Locale.ROOT, "%.1f us", us);
    }

    static Map<String, Object> row(int n, String op, Series series, Map<String, Object> extra) {
        Stats s = Stats.of(series.wall);
        Stats c = Stats.of(series.cpu);
        Map<String, Object> m = new LinkedHashMap<>();
        m.put("n", n);
        m.put("operation", op);
        m.put("reps", series.wall.length);
        m.put("meanUs", s.meanUs());
        m.put("p50Us", s.p50Us());
        m.put("p99Us", s.p99Us());
        m.put("maxUs", s.maxUs());
        m.put("cpuMeanUs", c.meanUs());
        m.put("cpuP50Us", c.p50Us());
        m.put("cpuP99Us", c.p99Us());
        m.putAll(new java.util.TreeMap<>(extra));
        return m;
    }

    static String toJson(Object o) {
        StringBuilder sb = new StringBuilder();
        write(sb, o, "");
        return sb.append('\n').toString();
    }

    private static void write(StringBuilder sb, Object o, String indent) {
        if (o instanceof Map<?, ?> m) {
            sb.append("{\n");
            int i = 0;
            for (Map.Entry<?, ?> e : m.entrySet()) {
                sb.append(indent).append("  \"").append(e.getKey()).append("\": ");
                write(sb, e.getValue(), indent + "  ");
                sb.append(++i < m.size() ? ",\n" : "\n");
            }
            sb.append(indent).append('}');
        } else if (o instanceof List<?> l) {
            sb.append("[\n");
            for (int i = 0; i < l.size(); i++) {
                sb.append(indent).append("  ");
                write(sb, l.get(i), indent + "  ");
                sb.append(i + 1 < l.size() ? ",\n" : "\n");
            }
            sb.append(indent).append(']');
        } else if (o instanceof String s) {
            sb.append('"').append(s.replace("\\", "\\\\").replace("\"", "\\\"")).append('"');
        } else if (o instanceof Double d) {
            sb.append(String.format(Locale.ROOT, "%.3f", d));
        } else {
            sb.append(o);
        }
    }
}
