package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertTrue;
import static org.junit.jupiter.api.Assertions.fail;

import com.sun.jna.Library;
import com.sun.jna.Native;
import java.io.BufferedReader;
import java.io.IOException;
import java.io.InputStreamReader;
import java.io.OutputStreamWriter;
import java.io.PrintWriter;
import java.io.Writer;
import java.nio.charset.StandardCharsets;
import java.nio.file.DirectoryStream;
import java.nio.file.Files;
import java.nio.file.Path;
import java.nio.file.StandardCopyOption;
import java.util.ArrayList;
import java.util.Comparator;
import java.util.List;
import java.util.Map;
import java.util.Set;
import java.util.TreeSet;
import java.util.concurrent.BlockingQueue;
import java.util.concurrent.LinkedBlockingQueue;
import java.util.concurrent.TimeUnit;
import java.util.concurrent.atomic.AtomicInteger;
import java.util.function.Predicate;
import java.util.regex.Matcher;
import java.util.regex.Pattern;
import java.util.stream.Stream;

/**
 * The assembled runtime as a child process: a private copy of the assembly (fresh bundle cache),
 * the freshly built DRCR, planner and contracts bundles, a unique runtime id. Commands go to
 * Gogo on stdin; each reply is delimited by an {@code echo} marker. Stderr (the DRCR's log) is
 * kept for failure messages. {@link #close()} stops the framework, waits for the JVM with a
 * deadline and asserts that nothing of this runtime is left: no shm, no queue, no process.
 */
final class Runtime implements AutoCloseable {

    private static final AtomicInteger SEQ = new AtomicInteger();
    private static final Pattern BUNDLE_ID = Pattern.compile("Bundle ID: (\\d+)");

    /** libc, for the queue leak check (/dev/mqueue may not be mounted). */
    interface LibC extends Library {
        LibC C = Native.load("c", LibC.class);

        int mq_open(String name, int oflag);

        int mq_close(int d);
    }

    final String rid;
    final Path dir;
    private final Process process;
    private final Writer stdin;
    private final BlockingQueue<String> out = new LinkedBlockingQueue<>();
    private final List<String> log = new ArrayList<>();
    private final Set<String> instancesSeen = new TreeSet<>();
    private int marker;

    Runtime(String name) throws IOException, InterruptedException {
        this(name, null);
    }

    /** A runtime with a given runtime id (null: a fresh unique one). */
    Runtime(String name, String fixedRid) throws IOException, InterruptedException {
        this(name, fixedRid, true);
    }

    /** @param waitForDrcr false: do not wait for the DRCR (a test that expects it to refuse to start) */
    Runtime(String name, String fixedRid, boolean waitForDrcr) throws IOException, InterruptedException {
        this(name, fixedRid, waitForDrcr, trustedFolders());
    }

    /**
     * @param trusted the code gate's trusted folders ({@code arflex.code.trusted}); the tests of
     *        the gate pass the runtime's defaults only ({@code bundle,cell,tools})
     */
    Runtime(String name, String fixedRid, boolean waitForDrcr, String trusted) throws IOException, InterruptedException {
        this(name, fixedRid, waitForDrcr, trusted, null);
    }

    /** @param umask the file mode creation mask to start the JVM with (octal), null: this JVM's */
    Runtime(String name, String fixedRid, boolean waitForDrcr, String trusted, String umask)
            throws IOException, InterruptedException {
        this(name, fixedRid, waitForDrcr, trusted, umask, List.of(), null, Map.of());
    }

    /** A runtime whose framework gets these properties too ("key=value", e.g. a heartbeat grace). */
    static Runtime withProperties(String name, String... properties) throws IOException, InterruptedException {
        return new Runtime(name, null, true, trustedFolders(), null, List.of(properties), null, Map.of());
    }

    /**
     * A runtime whose JVM gets these environment variables on top of this one's (as a unit
     * file's {@code Environment=} would give them), and these framework properties.
     */
    static Runtime withEnvironment(String name, Map<String, String> env, String... properties)
            throws IOException, InterruptedException {
        return new Runtime(name, null, true, trustedFolders(), null, List.of(properties), null, env);
    }

    /**
     * A runtime whose JVM runs on @jvmCpus only ({@code taskset -c}, e.g. "0"), with it the
     * non-real-time threads of every RT half it spawns (an RT thread sets its own affinity to
     * the CPU admission gave it): the setup of docs/latency.md for a CPU kept apart.
     */
    static Runtime pinned(String name, String jvmCpus, String... properties) throws IOException, InterruptedException {
        return new Runtime(name, null, true, trustedFolders(), null, List.of(properties), jvmCpus, Map.of());
    }

    private Runtime(String name, String fixedRid, boolean waitForDrcr, String trusted, String umask, List<String> properties,
            String jvmCpus, Map<String, String> env) throws IOException, InterruptedException {
        Path assembly = Path.of(System.getProperty("arflex.it.runtime"));
        if (!Files.isRegularFile(assembly.resolve("bin/felix.jar"))) {
            fail("runtime assembly not found at " + assembly + " (build management/runtime first)");
        }
        int n = SEQ.incrementAndGet();
        rid = fixedRid != null ? fixedRid : "it" + ProcessHandle.current().pid() + "-" + n;
        dir = Path.of(System.getProperty("arflex.it.work")).resolve(name + "-" + n);
        deleteTree(dir);
        copyTree(assembly, dir);
        for (String jar : System.getProperty("arflex.it.bundles").split(",")) {
            Path j = Path.of(jar.trim());
            assertTrue(Files.isRegularFile(j), "bundle to test not built: " + j);
            // the fresh build replaces the assembly's copy (same file name) or joins it
            Files.copy(j, dir.resolve("bundle").resolve(j.getFileName()), StandardCopyOption.REPLACE_EXISTING);
        }
        // The tests' RT halves skip mlockall (many runtimes one after the other on a small
        // machine); a benchmark that measures the cell as the main job runs it sets
        // arflex.it.mlock=true.
        boolean mlock = Boolean.getBoolean("arflex.it.mlock");
        List<String> command = new ArrayList<>();
        if (umask != null) {
            command.addAll(List.of("sh", "-c", "umask " + umask + " && exec \"$@\"", "sh"));
        }
        if (jvmCpus != null) {
            command.addAll(List.of("taskset", "-c", jvmCpus));
        }
        command.addAll(List.of(Path.of(System.getProperty("java.home"), "bin", "java").toString(),
                "-XX:+UseG1GC", "-XX:MaxGCPauseMillis=20",
                // the JVM's own pauses (GC, safepoints), in the runtime's folder, for whoever reads a stall
                "-Xlog:gc,safepoint:file=jvm-pauses.log:time,uptime",
                "-Darflex.runtime.id=" + rid, "-Darflex.nomlock=" + !mlock, "-Dorg.osgi.service.http.port=0",
                "-Darflex.code.trusted=" + trusted));
        // a test runtime: its RT halves honour rt-core's test faults, which the faulty versions
        // of the update tests set (D80); a test that proves a shipped half ignores them says false
        if (properties.stream().noneMatch(p -> p.startsWith("arflex.test.hooks="))) {
            command.add("-Darflex.test.hooks=true");
        }
        properties.forEach(p -> command.add("-D" + p));
        command.addAll(List.of("-jar", "bin/felix.jar"));
        ProcessBuilder pb = new ProcessBuilder(command).directory(dir.toFile());
        pb.environment().putAll(env);
        process = pb.start();
        stdin = new OutputStreamWriter(process.getOutputStream(), StandardCharsets.UTF_8);
        pump(new BufferedReader(new InputStreamReader(process.getInputStream(), StandardCharsets.UTF_8)), true);
        pump(new BufferedReader(new InputStreamReader(process.getErrorStream(), StandardCharsets.UTF_8)), false);
        this.expectDrcr = waitForDrcr;
        // The DRCR is ready when arflex:dto answers with JSON.
        if (waitForDrcr) {
            waitUntil("the DRCR to start", 60_000, () -> cmd("arflex:dto").startsWith("{"));
        }
    }

    /**
     * The code gate's trusted folders (docs/DECISIONS.md D12): the runtime's own, and where the
     * tests take their jars from (this checkout's builds, and the jars they write into temporary
     * folders). A test of the gate itself starts its runtime without them.
     */
    static String trustedFolders() {
        Path checkout = Path.of(System.getProperty("user.dir")).toAbsolutePath().getParent();
        return String.join(",", "bundle", "cell", "tools", checkout.toString(), System.getProperty("java.io.tmpdir"));
    }

    private void pump(BufferedReader r, boolean stdout) {
        Thread t = new Thread(() -> {
            try {
                String line;
                while ((line = r.readLine()) != null) {
                    if (stdout) {
                        out.add(line);
                    }
                    synchronized (log) {
                        log.add((stdout ? "out| " : "err| ") + line);
                    }
                }
            } catch (IOException ignored) {
                // process ended
            }
        }, "it-" + (stdout ? "out" : "err"));
        t.setDaemon(true);
        t.start();
    }

    /** The last lines of the runtime's output, for failure messages. */
    String tail() {
        synchronized (log) {
            return String.join("\n", log.subList(Math.max(0, log.size() - 80), log.size()));
        }
    }

    /** Sends one Gogo command and returns its output (prompts removed), waiting at most 60 s. */
    String cmd(String command) {
        return cmd(command, 60);
    }

    /** Sends one Gogo command and returns its output (prompts removed), waiting at most {@code seconds}. */
    synchronized String cmd(String command, long seconds) {
        String m = "__arflex_end_" + (++marker) + "__";
        try {
            stdin.write(command + "\necho " + m + "\n");
            stdin.flush();
            StringBuilder sb = new StringBuilder();
            long deadline = System.nanoTime() + TimeUnit.SECONDS.toNanos(seconds);
            while (true) {
                long left = deadline - System.nanoTime();
                String line = left > 0 ? out.poll(left, TimeUnit.NANOSECONDS) : null;
                if (line == null) {
                    fail("no reply to '" + command + "' within " + seconds + " s\n" + tail());
                }
                while (line.startsWith("g! ")) {
                    line = line.substring(3);
                }
                if (line.trim().equals(m)) {
                    return sb.toString().strip();
                }
                sb.append(line).append('\n');
            }
        } catch (IOException e) {
            throw new IllegalStateException("runtime stdin closed: " + e + "\n" + tail());
        } catch (InterruptedException e) {
            Thread.currentThread().interrupt();
            throw new IllegalStateException(e);
        }
    }

    /** Installs and starts a bundle through Felix's own commands; returns its id. */
    long installAndStart(Path jar) {
        long id = install(jar);
        String r = cmd("start " + id);
        assertTrue(r.isEmpty(), "start " + id + ": " + r + "\n" + tail());
        return id;
    }

    long install(Path jar) {
        String r = cmd("install " + jar.toUri());
        Matcher m = BUNDLE_ID.matcher(r);
        assertTrue(m.find(), "install " + jar + ": " + r);
        return Long.parseLong(m.group(1));
    }

    /** The cell DTO. */
    @SuppressWarnings("unchecked")
    Map<String, Object> dto() {
        String j = cmd("arflex:dto");
        Map<String, Object> d = (Map<String, Object>) JsonReader.parse(j);
        for (Map<String, Object> i : list(d, "instances")) {
            instancesSeen.add((String) i.get("name"));
        }
        return d;
    }

    @SuppressWarnings("unchecked")
    static List<Map<String, Object>> list(Map<String, Object> m, String key) {
        return (List<Map<String, Object>>) m.get(key);
    }

    /** The instance DTO, or null. */
    Map<String, Object> instance(String name) {
        return list(dto(), "instances").stream().filter(i -> name.equals(i.get("name"))).findFirst().orElse(null);
    }

    String state(String name) {
        Map<String, Object> i = instance(name);
        return i == null ? null : (String) i.get("state");
    }

    /** One snapshot: the instance is ACTIVE with a running process other than {@code oldPid}. */
    boolean activeWithNewPid(String name, long oldPid) {
        Map<String, Object> i = instance(name);
        if (i == null || !"ACTIVE".equals(i.get("state"))) {
            return false;
        }
        long pid = ((Number) i.get("pid")).longValue();
        return pid != 0 && pid != oldPid;
    }

    long pid(String name) {
        return ((Number) instance(name).get("pid")).longValue();
    }

    /** Waits (polling the DTO, deadline) until every named instance is in {@code state}. */
    void awaitState(String state, long timeoutMs, String... names) {
        waitUntil(String.join(",", names) + " " + state, timeoutMs, () -> {
            for (String n : names) {
                if (!state.equals(state(n))) {
                    return false;
                }
            }
            return true;
        });
    }

    interface Cond extends Polling.Cond {
    }

    /** Returns when the condition held; fails on the deadline with arflex:list and the log, and when interrupted. */
    void waitUntil(String what, long timeoutMs, Cond c) {
        Polling.until(what, timeoutMs, c, () -> {
            String state;
            try {
                state = process.isAlive() ? cmd("arflex:list") : "(runtime exited)";
            } catch (RuntimeException e) {
                state = e.toString();
            }
            return "\n--- arflex:list\n" + state + "\n--- runtime output\n" + tail();
        });
    }

    /** The pid of this runtime's JVM (found by its runtime id on the command line). */
    long jvmPid() throws IOException {
        try (DirectoryStream<Path> ds = Files.newDirectoryStream(Path.of("/proc"))) {
            for (Path p : ds) {
                if (!p.getFileName().toString().matches("\\d+")) {
                    continue;
                }
                try {
                    String cl = new String(Files.readAllBytes(p.resolve("cmdline")), StandardCharsets.UTF_8);
                    if (cl.contains("-Darflex.runtime.id=" + rid + "\0")) {
                        return Long.parseLong(p.getFileName().toString());
                    }
                } catch (IOException ignored) {
                    // ended while we looked
                }
            }
        }
        fail("runtime JVM of " + rid + " not found");
        return -1;
    }

    /**
     * As scripts/run-cell.sh does for the main job: every thread of the runtime JVM (whose
     * heartbeat the 1 ms components watch with a 100 ms timeout) to {@code nice}, above the
     * cell's best-effort rendering and vision (nice 19). Needs root or CAP_SYS_NICE; without it
     * the JVM keeps its priority. Returns a line saying which.
     */
    String renice(int nice) throws IOException, InterruptedException {
        long jvm = jvmPid();
        List<String> cmd = new ArrayList<>(List.of("renice", "-n", Integer.toString(nice), "-p"));
        try (DirectoryStream<Path> ds = Files.newDirectoryStream(Path.of("/proc/" + jvm + "/task"))) {
            ds.forEach(t -> cmd.add(t.getFileName().toString()));
        }
        Process p = new ProcessBuilder(cmd).redirectErrorStream(true).start();
        String o = new String(p.getInputStream().readAllBytes(), StandardCharsets.UTF_8);
        return p.waitFor() == 0 ? "runtime JVM " + jvm + " at nice " + nice + " (" + (cmd.size() - 4) + " threads)"
                : "runtime JVM left at its priority (renice: " + o.strip() + ")";
    }

    /** An output port segment of an instance of this runtime. */
    Path segment(String instance, String port) {
        return Path.of("/dev/shm/arflex." + rid + "." + instance + ".out." + port);
    }

    /** Names of this runtime's shm objects. */
    List<String> shmObjects() throws IOException {
        List<String> l = new ArrayList<>();
        try (DirectoryStream<Path> ds = Files.newDirectoryStream(Path.of("/dev/shm"), "arflex." + rid + ".*")) {
            ds.forEach(p -> l.add(p.toString()));
        }
        return l;
    }

    /**
     * Processes (anywhere) started for this runtime id: "pid: command line ", every argument
     * followed by a space, so {@code contains("--instance " + name + " ")} matches that whole
     * instance name (the launcher passes {@code --instance} last: trimmed, such a check never
     * matched and "no process of X" held vacuously).
     */
    static List<String> rtProcesses(String rid) throws IOException {
        List<String> l = new ArrayList<>();
        try (DirectoryStream<Path> ds = Files.newDirectoryStream(Path.of("/proc"))) {
            for (Path p : ds) {
                if (!p.getFileName().toString().matches("\\d+")) {
                    continue;
                }
                try {
                    String cl = new String(Files.readAllBytes(p.resolve("cmdline")), StandardCharsets.UTF_8).replace('\0', ' ');
                    if (cl.contains("--runtime " + rid + " ")) {
                        l.add(p.getFileName() + ": " + cl.strip() + " ");
                    }
                } catch (IOException ignored) {
                    // process ended while we looked
                }
            }
        }
        return l;
    }

    private boolean crashed;
    private boolean expectDrcr = true;

    /** Kills the runtime's JVM with SIGKILL (its RT halves stay behind, as after a real crash). */
    void crash() throws InterruptedException {
        crashed = true;
        process.destroyForcibly();
        process.waitFor(30, TimeUnit.SECONDS);
    }

    /** How many lines the log has now (a mark for {@link #logSince}). */
    int logMark() {
        synchronized (log) {
            return log.size();
        }
    }

    /** The log lines after {@code mark}. */
    List<String> logSince(int mark) {
        synchronized (log) {
            return new ArrayList<>(log.subList(Math.min(mark, log.size()), log.size()));
        }
    }

    /** Whether the log contains a line with {@code text}. */
    boolean logContains(String text) {
        synchronized (log) {
            return log.stream().anyMatch(l -> l.contains(text));
        }
    }

    /** Stops the framework and checks that nothing of this runtime is left behind. */
    @Override
    public void close() throws Exception {
        if (crashed) {
            return; // what it left is the next runtime's to sweep (and that runtime's check)
        }
        try {
            if (process.isAlive()) {
                try {
                    stdin.write("stop 0\n");
                    stdin.close();
                } catch (IOException ignored) {
                    // already gone
                }
            }
            if (!process.waitFor(60, TimeUnit.SECONDS)) {
                process.destroyForcibly();
                process.waitFor(10, TimeUnit.SECONDS);
                fail("runtime did not stop within 60 s\n" + tail());
            }
        } finally {
            process.descendants().forEach(ProcessHandle::destroyForcibly);
        }
        synchronized (log) {
            if (!expectDrcr) {
                deleteTree(dir);
                return; // a runtime whose DRCR was expected to refuse to start
            }
            List<String> thrown = log.stream().filter(l -> l.contains("at org.arflex.drcr")).toList();
            assertTrue(thrown.isEmpty(), "stack traces of the DRCR in the runtime log:\n" + tail());
        }
        List<String> leaks = new ArrayList<>(shmObjects());
        for (String inst : instancesSeen) {
            for (String ch : new String[] {"cmd", "rsp"}) {
                String q = "/arflex." + rid + "." + inst + "." + ch;
                int d = LibC.C.mq_open(q, 0);
                if (d >= 0) {
                    LibC.C.mq_close(d);
                    leaks.add("mq " + q);
                }
            }
        }
        leaks.addAll(rtProcesses(rid));
        assertTrue(leaks.isEmpty(), "left behind by runtime " + rid + ": " + leaks + "\n" + tail());
        deleteTree(dir);
    }

    static void copyTree(Path from, Path to) throws IOException {
        try (Stream<Path> s = Files.walk(from)) {
            for (Path p : (Iterable<Path>) s::iterator) {
                if (from.relativize(p).startsWith("felix-cache")) {
                    continue; // every test starts with a fresh bundle cache
                }
                Path t = to.resolve(from.relativize(p).toString());
                if (Files.isDirectory(p)) {
                    Files.createDirectories(t);
                } else {
                    Files.copy(p, t, StandardCopyOption.REPLACE_EXISTING);
                }
            }
        }
    }

    static void deleteTree(Path p) throws IOException {
        if (!Files.exists(p)) {
            return;
        }
        try (Stream<Path> s = Files.walk(p)) {
            s.sorted(Comparator.reverseOrder()).forEach(f -> f.toFile().delete());
        }
    }

    /** The instance names a predicate selects. */
    static List<String> names(Map<String, Object> dto, Predicate<Map<String, Object>> p) {
        return list(dto, "instances").stream().filter(p).map(i -> (String) i.get("name")).toList();
    }
}
