package org.arflex.it;

import java.nio.file.DirectoryStream;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.Collections;
import java.util.List;
import java.util.Locale;
import java.util.Map;
import java.util.Random;
import java.util.concurrent.ExecutorService;
import java.util.concurrent.Executors;
import java.util.concurrent.Future;
import java.util.concurrent.atomic.AtomicInteger;
import java.util.concurrent.locks.ReentrantReadWriteLock;
import java.util.regex.Matcher;
import java.util.regex.Pattern;
import org.junit.jupiter.api.Test;

/**
 * Supervision that never stalls and never leaks, over many cycles (issue 17): while an unrelated
 * 1 kHz component runs (sample-counter with a 1 ms period), {@code arflex.bench.threads} workers
 * each churn one component through install, Felix {@code update} and uninstall
 * ({@code arflex.bench.cycles} cycles in all, over sample-scaler and debug-monitor: one worker
 * each, at most two), and {@code arflex.bench.kills} kill -9 of a random running RT half of the
 * churned components are spread over the run (the unrelated component is never killed: its
 * latency is what is measured).
 * Every {@code arflex.bench.every} cycles every worker and the kill loop pause between two steps:
 * the counter is measured over a quiet window ({@code arflex.bench.quietms}, 3 s), then the
 * runtime JVM is sampled (heap after a full GC, threads, fds) with the cell's objects (shm, mq,
 * RT processes). Quiet and churn windows alternate over the whole run. Prints a table, writes
 * target/bench/soak.json, and ends with
 * {@code soak: C cycles, K kills, heap slope S KB/1000 cycles, leaks L, max supervision stall X ms}.
 *
 * <p>"Supervision stall" is the longest time the DRCR's supervision was not answering: the
 * longest wait of a task for the DRCR's actor (a crash report, a hang kill, a command; logged by
 * the actor, D33) or the longest silence of its heartbeat round (a JVM stall, D17), whichever is
 * longer. The longest {@code arflex:list} round trip through the shell is printed beside it: the
 * workers share the runtime's one Gogo session, so it also waits for a worker's Felix
 * {@code update} or {@code uninstall} in progress, which is Felix's bundle work, not
 * supervision. Not a test: run by {@code ./arflex bench soak} only.
 */
class SoakBench {

    private static final Pattern SILENT = Pattern.compile("heartbeat round was silent for (\\d+) ms");
    private static final Pattern ACTOR = Pattern.compile("the actor answered after (\\d+) ms");
    private static final long T = 60_000;

    private final List<Double> detections = Collections.synchronizedList(new ArrayList<>());
    /** From the exit seen (reaper thread) to the actor's handling of it, as the DRCR's line says. */
    private final List<Double> handlings = Collections.synchronizedList(new ArrayList<>());
    private final List<long[]> samples = Collections.synchronizedList(new ArrayList<>()); // cycles, heapKB, threads, fds, shm, mq, procs
    private final AtomicInteger cycles = new AtomicInteger();
    private long stopAtNs;
    /** Each step of a cycle, from the Felix command to the state it leads to, as the shell sees it (ms). */
    private final List<Double> installs = Collections.synchronizedList(new ArrayList<>());
    private final List<Double> updates = Collections.synchronizedList(new ArrayList<>());
    private final List<Double> uninstalls = Collections.synchronizedList(new ArrayList<>());
    private volatile long maxShellMs;
    private long maxStallMs;
    private int frozenEvery;
    private final AtomicInteger frozenDone = new AtomicInteger();
    /** The bench's own full GCs (jcmd GC.run, for heap after GC): [start, end] wall time. */
    private final List<java.time.LocalTime[]> forcedGcs = Collections.synchronizedList(new ArrayList<>());
    private long maxForcedGcStallMs;

    /** Workers and the kill loop hold it shared for one step; a sample holds it alone. */
    private final ReentrantReadWriteLock quiesce = new ReentrantReadWriteLock(true);
    /** The 1 kHz counter in the quiet windows, and between them (the churn). */
    private final CellChurnBench.Tally quiet = new CellChurnBench.Tally();
    private final CellChurnBench.Tally busy = new CellChurnBench.Tally();
    private CellChurnBench.Snap churnFrom; // under the write lock
    private final long quietMs = Long.getLong("arflex.bench.quietms", 3000);
    private Runtime srt;
    private long sjvm;
    private String srid;
    private static final long PERIOD_NS = 1_000_000L;

    /** The 1 kHz unrelated component. */
    private static Path counter1kHz(boolean apart) throws Exception {
        return Jars.withContract(CellIT.COUNTER, Files.createTempDirectory("arflex-soak").resolve("counter-1khz.jar"),
                xml -> xml.replace("period=\"10ms\" deadline=\"10ms\"",
                        "period=\"1ms\" deadline=\"1ms\"" + (apart ? " cpus=\"1\" exclusive=\"true\"" : "")));
    }

    /**
     * The counter's CPU kept apart (default; {@code arflex.bench.sharedcpu} turns it off), as
     * docs/latency.md does for the probe: the counter holds CPU 1 exclusively, the runtime
     * reserves it ({@code arflex.cpus.reserved=1}: the churned halves are placed on CPU 0), and
     * the JVM runs on CPU 0 with the spawns' non-RT threads, so the churn's process creation,
     * exits and the JVM's own work run beside the counter, not on its CPU.
     */
    private static Runtime runtime(boolean apart) throws Exception {
        return apart ? Runtime.pinned("soak", "0", "arflex.cpus=0,1", "arflex.cpus.reserved=1") : new Runtime("soak");
    }

    @Test
    void soak() throws Exception {
        int total = Integer.getInteger("arflex.bench.cycles", 300);
        // a time bound (arflex.bench.minutes, 0: none): no cycle starts after it, and the report
        // says how many cycles were done
        long minutes = Long.getLong("arflex.bench.minutes", 0);
        stopAtNs = System.nanoTime() + (minutes > 0 ? minutes * 60_000_000_000L : Long.MAX_VALUE / 2);
        int kills = Integer.getInteger("arflex.bench.kills", 30);
        int threads = Math.max(1, Math.min(2, Integer.getInteger("arflex.bench.threads", 2)));
        int every = Math.max(1, Integer.getInteger("arflex.bench.every", Math.max(1, total / 10)));
        // every N-th cycle of a worker: its half is SIGSTOPped and the bundle uninstalled (issue 17:
        // the supervision must not stall while a frozen half is stopped); 0: never
        frozenEvery = Integer.getInteger("arflex.bench.frozen", 10);
        Path[] churn = {CellIT.SCALER, DebugMonitorIT.DEBUGMON};
        String[] names = {"sample-scaler", "debug-monitor"};
        String rid;
        int killed = 0;
        boolean apart = !Boolean.getBoolean("arflex.bench.sharedcpu") && java.lang.Runtime.getRuntime().availableProcessors() >= 2;
        System.out.println("soak: the counter's CPU " + (apart ? "kept apart (CPU 1 exclusive and reserved, the JVM on CPU 0)"
                : "shared with the churn and the JVM"));
        try (Runtime rt = runtime(apart)) {
            rid = rt.rid;
            rt.installAndStart(counter1kHz(apart));
            rt.awaitState("ACTIVE", T, "sample-counter");
            srt = rt;
            sjvm = rt.jvmPid();
            srid = rid;
            sampleQuietly(); // the first quiet window and heap sample, before any churn

            Random rnd = new Random(Long.getLong("arflex.bench.seed", System.nanoTime()));
            ExecutorService pool = Executors.newFixedThreadPool(threads);
            List<Future<?>> workers = new ArrayList<>();
            for (int w = 0; w < threads; w++) {
                int k = w;
                workers.add(pool.submit(() -> {
                    int mine = 0;
                    while (cycles.get() < total && System.nanoTime() - stopAtNs < 0) {
                        boolean frozen = frozenEvery > 0 && ++mine % frozenEvery == 0;
                        int c;
                        quiesce.readLock().lock();
                        try {
                            cycle(rt, churn[k], names[k], frozen);
                            c = cycles.incrementAndGet();
                        } finally {
                            quiesce.readLock().unlock();
                        }
                        if (c % every == 0) {
                            sampleQuietly();
                        }
                    }
                    return null;
                }));
            }
            // kills spread over the run, from this thread, with the shell answering in between
            int killEvery = kills == 0 ? Integer.MAX_VALUE : Math.max(1, total / kills);
            // each kill in the middle of its share of the cycles: due at the share's end, the last
            // one came due as the workers finished and was sometimes never made (999 of 1000)
            int nextKill = Math.max(1, killEvery / 2);
            java.util.concurrent.CompletableFuture<Object> anyDone = new java.util.concurrent.CompletableFuture<>();
            while (workers.stream().anyMatch(f -> !f.isDone())) {
                quiesce.readLock().lock();
                try {
                    long t0 = System.nanoTime();
                    rt.cmd("arflex:list");
                    maxShellMs = Math.max(maxShellMs, (System.nanoTime() - t0) / 1_000_000L);
                    // a kill is due: tried at every probe until a churned half is running
                    if (killed < kills && cycles.get() >= nextKill && killRandom(rt, rnd)) {
                        killed++;
                        nextKill += killEvery;
                    }
                } finally {
                    quiesce.readLock().unlock();
                }
                // a probe every 20 ms: back to back, the probes would hold the one shell session
                // the workers' Felix commands need, and the bench would measure its own queue
                try {
                    anyDone.get(20, java.util.concurrent.TimeUnit.MILLISECONDS);
                } catch (java.util.concurrent.TimeoutException e) {
                    // the next probe
                }
            }
            for (Future<?> f : workers) {
                f.get(); // a worker's failure is the bench's failure
            }
            pool.shutdown();
            if (samples.isEmpty() || samples.get(samples.size() - 1)[0] != cycles.get()) {
                sampleQuietly(); // the last churn window ends here
            }
            readKills(rt);
            List<String> all = rt.logSince(0);
            for (int li = 0; li < all.size(); li++) {
                String l = all.get(li);
                if (l.contains("rewiring failed") || l.contains("did not answer") || l.contains("an actor task has run")) {
                    System.out.println("soak: log " + l); // a half that did not take a command in time
                }
                for (Pattern p : new Pattern[] {SILENT, ACTOR}) {
                    Matcher m = p.matcher(l);
                    if (m.find()) {
                        long ms = Long.parseLong(m.group(1));
                        if (duringForcedGc(l, ms, p == SILENT ? 100 : 10)) {
                            maxForcedGcStallMs = Math.max(maxForcedGcStallMs, ms);
                            System.out.println("soak: log (the bench's own full GC) " + l);
                        } else {
                            maxStallMs = Math.max(maxStallMs, ms);
                            System.out.println("soak: log " + l); // which stall, and when
                            if (ms >= 50) {
                                // what the runtime said just before: whoever held the actor or the JVM
                                all.subList(Math.max(0, li - 40), li).stream().filter(c -> c.startsWith("err| ")).skip(0)
                                        .forEach(c -> System.out.println("soak:   before: " + c.substring(0, Math.min(c.length(), 220))));
                            }
                        }
                    }
                }
            }
            jvmPauses(rt.dir.resolve("jvm-pauses.log"));
            if (Boolean.getBoolean("arflex.bench.histogram")) {
                // what the heap holds after the churn: the classes with the most bytes
                Jcmd.run(sjvm, "GC.class_histogram").lines().limit(25)
                        .forEach(l -> System.out.println("soak: histogram " + l));
            }
        }
        int leaks = FaultBench.leftovers(rid, "soak");
        report(total, killed, leaks);
    }

    /** One install -> update -> uninstall of one component. */
    private void cycle(Runtime rt, Path jar, String name, boolean frozen) throws Exception {
        long t0 = System.nanoTime();
        long id = rt.installAndStart(jar);
        rt.awaitState("ACTIVE", T, name);
        long t1 = step(installs, t0);
        long pid = rt.pid(name);
        if (frozen && Signals.tryToSend(pid, "STOP")) {
            // a frozen half answers nothing: the DRCR kills it after its shutdown deadline
            String r = rt.cmd("uninstall " + id);
            if (!r.isBlank()) {
                throw new AssertionError("uninstall of a frozen half " + id + ": " + r);
            }
            rt.waitUntil(name + " (frozen) gone", T, () -> rt.instance(name) == null
                    && ProcessHandle.of(pid).map(h -> !h.isAlive()).orElse(true));
            frozenDone.incrementAndGet();
            return;
        }
        String u = rt.cmd("update " + id);
        if (!u.isBlank()) {
            throw new AssertionError("update " + id + ": " + u);
        }
        rt.waitUntil(name + " back after the update", T, () -> rt.activeWithNewPid(name, pid));
        long t2 = step(updates, t1);
        String r = rt.cmd("uninstall " + id);
        if (!r.isBlank()) {
            throw new AssertionError("uninstall " + id + ": " + r);
        }
        rt.waitUntil(name + " gone", T, () -> rt.instance(name) == null);
        step(uninstalls, t2);
    }

    /** Records the step that began at @t0 (ms, as the bench's shell sees it); returns now. */
    private static long step(List<Double> into, long t0) {
        long now = System.nanoTime();
        into.add((now - t0) / 1e6);
        return now;
    }

    /** kill -9 of a random running RT half; the detection time is from the kill to the DRCR's line. */
    private boolean killRandom(Runtime rt, Random rnd) throws Exception {
        List<Map<String, Object>> live = new ArrayList<>();
        for (Map<String, Object> i : Runtime.list(rt.dto(), "instances")) {
            if (!"sample-counter".equals(i.get("name")) && "ACTIVE".equals(i.get("state"))
                    && ((Number) i.get("pid")).longValue() > 0) {
                live.add(i);
            }
        }
        if (live.isEmpty()) {
            return false;
        }
        Map<String, Object> victim = live.get(rnd.nextInt(live.size()));
        String name = (String) victim.get("name");
        long pid = ((Number) victim.get("pid")).longValue();
        int mark = rt.logMark();
        java.time.LocalTime at = java.time.LocalTime.now();
        if (!Signals.tryToSend(pid, "9")) {
            return false; // it went away by itself (an uninstall) in between
        }
        // read from the log at the end: waiting here for the DRCR's lines held the probe loop
        // (and, behind a sample waiting for the lock, every worker) for seconds per kill
        kills.add(new Kill(mark, at, name + " (pid " + pid + ") "));
        return true;
    }

    /** The runtime JVM's safepoint pauses (its -Xlog:safepoint) over 20 ms, the bench's own full GCs among them. */
    private static void jvmPauses(Path log) throws Exception {
        if (!Files.isRegularFile(log)) {
            return;
        }
        Pattern total = Pattern.compile("Safepoint \"([^\"]+)\".*Total: (\\d+) ns");
        int over = 0;
        long max = 0;
        for (String l : Files.readAllLines(log)) {
            Matcher m = total.matcher(l);
            if (m.find()) {
                long ms = Long.parseLong(m.group(2)) / 1_000_000L;
                if (ms >= 20) {
                    over++;
                    max = Math.max(max, ms);
                    System.out.println("soak: JVM pause " + ms + " ms: " + m.group(1) + " " + l.split(" ", 2)[0]);
                }
            }
        }
        System.out.printf(Locale.ROOT, "soak: JVM safepoint pauses over 20 ms: %d, longest %d ms (jvm-pauses.log)%n", over, max);
    }

    /** One kill -9: the log mark and wall time just before it, and how the DRCR names the half. */
    private record Kill(int mark, java.time.LocalTime at, String who) {
    }

    private final List<Kill> kills = new ArrayList<>();

    /** Detection and handling of every kill, from the runtime's log (the last one waited for). */
    private void readKills(Runtime rt) {
        if (!kills.isEmpty()) {
            Kill last = kills.get(kills.size() - 1);
            FaultBench.detection(rt, last.mark(), last.at(), last.who()); // its lines may still be on their way
            handled(rt, last.mark(), last.who());
        }
        Pattern p = Pattern.compile("\\(handled ([0-9.]+) ms after the exit was seen\\)");
        for (Kill k : kills) {
            List<String> after = rt.logSince(k.mark());
            after.stream().filter(l -> l.contains(k.who())).findFirst().ifPresent(l -> {
                try {
                    detections.add(java.time.Duration.between(k.at(),
                            java.time.LocalTime.parse(l.replace("err| ", "").split(" ", 2)[0])).toNanos() / 1e6);
                } catch (java.time.format.DateTimeParseException e) {
                    // not a line of the DRCR's log
                }
            });
            after.stream().filter(l -> l.contains(k.who())).map(p::matcher).filter(Matcher::find).findFirst()
                    .ifPresent(m -> handlings.add(Double.parseDouble(m.group(1))));
        }
    }

    /** The actor's "(handled X ms after the exit was seen)" for @who, or -1 (not within 10 s). */
    private static double handled(Runtime rt, int mark, String who) {
        Pattern p = Pattern.compile("\\(handled ([0-9.]+) ms after the exit was seen\\)");
        double[] ms = {-1};
        try {
            rt.waitUntil("the DRCR's handling of " + who, 10_000, () -> rt.logSince(mark).stream()
                    .filter(l -> l.contains(who)).map(p::matcher).filter(Matcher::find).findFirst()
                    .map(m -> ms[0] = Double.parseDouble(m.group(1))).isPresent());
        } catch (AssertionError e) {
            return -1;
        }
        return ms[0];
    }

    /**
     * True when a stall of @ms reported by @line (a heartbeat round's silence, reported at the
     * round after it, or an actor's wait, reported when it ends; @slackMs for the report)
     * overlaps one of the bench's own full GCs.
     */
    private boolean duringForcedGc(String line, long ms, long slackMs) {
        java.time.LocalTime end;
        try {
            end = java.time.LocalTime.parse(line.replace("err| ", "").split(" ", 2)[0]);
        } catch (java.time.format.DateTimeParseException e) {
            return false;
        }
        java.time.LocalTime start = end.minusNanos((ms + slackMs) * 1_000_000L);
        synchronized (forcedGcs) {
            return forcedGcs.stream().anyMatch(w -> !w[1].isBefore(start) && !w[0].isAfter(end));
        }
    }

    private static CellChurnBench.Snap snap(Runtime rt) {
        return CellChurnBench.Snap.of(rt.instance("sample-counter"), System.nanoTime());
    }

    /**
     * With every worker and the kill loop between two steps (nothing churns): ends the churn
     * window, measures the counter over a quiet window, then takes the heap after a full GC and
     * the counts; the next churn window starts when it returns. Quiet and churn windows thus
     * alternate over the whole run, so both see the same machine (a short quiet window at the
     * start only would compare 5 s against an hour), and no worker allocates between the GC and
     * the reading of the heap (with one running, the "heap after GC" was anything up to 135 MB).
     */
    private void sampleQuietly() throws Exception {
        quiesce.writeLock().lock();
        try {
            CellChurnBench.Snap q0 = snap(srt);
            if (churnFrom != null) {
                busy.add(churnFrom, q0, PERIOD_NS, false);
            }
            long end = System.nanoTime() + quietMs * 1_000_000L;
            srt.waitUntil("the quiet window", quietMs + T, () -> System.nanoTime() > end);
            quiet.add(q0, snap(srt), PERIOD_NS, false);
            sample(srt, sjvm, srid);
            churnFrom = snap(srt);
        } finally {
            quiesce.writeLock().unlock();
        }
    }

    /** Heap after a full GC (KB), threads and fds of the JVM; the cell's shm, mq and RT processes. */
    private void sample(Runtime rt, long jvm, String rid) throws Exception {
        java.time.LocalTime gc0 = java.time.LocalTime.now();
        Jcmd.run(jvm, "GC.run");
        forcedGcs.add(new java.time.LocalTime[] {gc0, java.time.LocalTime.now()});
        String info = Jcmd.run(jvm, "GC.heap_info");
        Matcher m = Pattern.compile("used (\\d+)K").matcher(info);
        long heapKb = m.find() ? Long.parseLong(m.group(1)) : -1;
        long threads = 0;
        for (String l : Files.readAllLines(Path.of("/proc/" + jvm + "/status"))) {
            if (l.startsWith("Threads:")) {
                threads = Long.parseLong(l.substring(8).trim());
            }
        }
        long fds;
        try (var s = Files.list(Path.of("/proc/" + jvm + "/fd"))) {
            fds = s.count();
        }
        long shm = count("/dev/shm", rid);
        long mq = count("/dev/mqueue", rid);
        long procs = Runtime.rtProcesses(rid).size();
        long c = cycles.get();
        samples.add(new long[] {c, heapKb, threads, fds, shm, mq, procs});
        System.out.printf(Locale.ROOT, "soak: %6d cycles  heap %7d KB  threads %4d  fds %4d  shm %3d  mq %3d  procs %2d%n", c,
                heapKb, threads, fds, shm, mq, procs);
    }

    private static long count(String dir, String rid) throws Exception {
        if (!Files.isDirectory(Path.of(dir))) {
            return 0;
        }
        long n = 0;
        try (DirectoryStream<Path> ds = Files.newDirectoryStream(Path.of(dir), "arflex." + rid + ".*")) {
            for (Path ignored : ds) {
                n++;
            }
        }
        return n;
    }

    /**
     * Slope of heap-after-GC against cycles, in KB per 1000 cycles: the median of the slopes
     * between every two samples (Theil-Sen), so one sample that a collection did not bring down
     * does not decide it; the first sample is dropped (warm-up).
     */
    static double slopeKbPer1000(List<long[]> s) {
        List<long[]> use = s.size() > 2 ? s.subList(1, s.size()) : s;
        List<Double> slopes = new ArrayList<>();
        for (int i = 0; i < use.size(); i++) {
            for (int j = i + 1; j < use.size(); j++) {
                long dx = use.get(j)[0] - use.get(i)[0];
                if (dx != 0) {
                    slopes.add((double) (use.get(j)[1] - use.get(i)[1]) / dx * 1000.0);
                }
            }
        }
        if (slopes.isEmpty()) {
            return Double.NaN;
        }
        Collections.sort(slopes);
        int n = slopes.size();
        return n % 2 == 1 ? slopes.get(n / 2) : (slopes.get(n / 2 - 1) + slopes.get(n / 2)) / 2;
    }

    private void report(int total, int killed, int leaks)
            throws Exception {
        List<Double> d = new ArrayList<>(detections);
        Collections.sort(d);
        List<Double> h = new ArrayList<>(handlings);
        Collections.sort(h);
        double slope = slopeKbPer1000(samples);
        long[] first = samples.get(0);
        long[] last = samples.get(samples.size() - 1);
        System.out.println("soak: quantity              first      last");
        String[] label = {"heap after GC (KB)", "JVM threads", "JVM fds", "shm objects", "mq objects", "RT processes"};
        for (int i = 0; i < label.length; i++) {
            System.out.printf(Locale.ROOT, "soak: %-20s %8d  %8d%n", label[i], first[i + 1], last[i + 1]);
        }
        System.out.printf(Locale.ROOT, "soak: 1 kHz counter      quiet p99 %s us, overruns %d in %d cycles (%s per 100k) | churn p99 %s us, overruns %d in %d cycles (%s per 100k)%n",
                us(quiet.quantileUs(0.99)), quiet.overruns, quiet.cycles, num(per100k(quiet)),
                us(busy.quantileUs(0.99)), busy.overruns, busy.cycles, num(per100k(busy)));
        System.out.printf(Locale.ROOT, "soak: exit detection     p50 %s ms, p99 %s ms, max %s ms (%d kills)%n", ms(pct(d, 50)),
                ms(pct(d, 99)), ms(d.isEmpty() ? Double.NaN : d.get(d.size() - 1)), d.size());
        System.out.printf(Locale.ROOT, "soak: exit handled after p50 %s ms, p99 %s ms, max %s ms (the actor's queue)%n",
                ms(pct(h, 50)), ms(pct(h, 99)), ms(h.isEmpty() ? Double.NaN : h.get(h.size() - 1)));
        for (Object[] st : new Object[][] {{"install -> ACTIVE", installs}, {"update -> ACTIVE", updates}, {"uninstall -> gone", uninstalls}}) {
            @SuppressWarnings("unchecked")
            List<Double> v = new ArrayList<>((List<Double>) st[1]);
            Collections.sort(v);
            System.out.printf(Locale.ROOT, "soak: %-19s p50 %s ms, p99 %s ms (%d, through the shell)%n", st[0], ms(pct(v, 50)),
                    ms(pct(v, 99)), v.size());
        }
        System.out.printf(Locale.ROOT, "soak: frozen halves      %d SIGSTOPped and uninstalled (every %d-th cycle of a worker)%n",
                frozenDone.get(), frozenEvery);
        System.out.printf(Locale.ROOT, "soak: stalls in the bench's own full GCs (jcmd GC.run): max %d ms, not counted%n",
                maxForcedGcStallMs);
        System.out.printf(Locale.ROOT, "soak: shell round trip   max %d ms (arflex:list behind the workers' Felix commands)%n",
                maxShellMs);
        StringBuilder js = new StringBuilder();
        for (long[] v : samples) {
            js.append(js.length() == 0 ? "" : ",").append(String.format(Locale.ROOT,
                    "{\"cycles\":%d,\"heap_kb\":%d,\"threads\":%d,\"fds\":%d,\"shm\":%d,\"mq\":%d,\"procs\":%d}", v[0], v[1], v[2],
                    v[3], v[4], v[5], v[6]));
        }
        Path out = Path.of(System.getProperty("arflex.bench.out", "target/bench/soak.json"));
        Files.createDirectories(out.toAbsolutePath().getParent());
        Files.writeString(out, String.format(Locale.ROOT,
                "{\"cycles\":%d,\"kills\":%d,\"heap_slope_kb_per_1000\":%s,\"leaks\":%d,\"max_supervision_stall_ms\":%d,"
                        + "\"max_shell_ms\":%d,\"detect_ms\":{\"p50\":%s,\"p99\":%s},\"handled_ms\":{\"p50\":%s,\"p99\":%s},\"quiet\":%s,\"churn\":%s,\"samples\":[%s]}%n",
                cycles.get(), killed, num(slope), leaks, maxStallMs, maxShellMs, num(pct(d, 50)), num(pct(d, 99)), num(pct(h, 50)), num(pct(h, 99)), quiet.json(), busy.json(), js));
        System.out.println("JSON: " + out.toAbsolutePath());
        System.out.printf(Locale.ROOT, "soak: %d cycles, %d kills, heap slope %.0f KB/1000 cycles, leaks %d, max supervision stall %d ms%n",
                cycles.get(), killed, slope, leaks, maxStallMs);
    }

    private static double per100k(CellChurnBench.Tally t) {
        return t.cycles == 0 ? Double.NaN : Math.round(t.overruns * 1e6 / t.cycles) / 10.0;
    }

    private static double pct(List<Double> sorted, double p) {
        if (sorted.isEmpty()) {
            return Double.NaN;
        }
        int i = (int) Math.ceil(p / 100.0 * sorted.size()) - 1;
        return sorted.get(Math.max(0, Math.min(sorted.size() - 1, i)));
    }

    private static String ms(double v) {
        return Double.isNaN(v) ? "-" : String.format(Locale.ROOT, "%.1f", v);
    }

    private static String us(double v) {
        return Double.isNaN(v) ? "-" : String.format(Locale.ROOT, "%.0f", v);
    }

    private static String num(double v) {
        return Double.isNaN(v) || Double.isInfinite(v) ? "null" : String.format(Locale.ROOT, "%.2f", v);
    }
}
