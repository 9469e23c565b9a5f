package org.arflex.it;

import com.sun.net.httpserver.HttpServer;
import java.io.IOException;
import java.io.InputStream;
import java.io.OutputStream;
import java.net.InetSocketAddress;
import java.net.ServerSocket;
import java.net.Socket;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.nio.file.attribute.PosixFilePermission;
import java.util.ArrayList;
import java.util.List;
import java.util.Map;
import java.util.Set;
import java.util.concurrent.ConcurrentHashMap;
import java.util.jar.Attributes;
import java.util.jar.JarEntry;
import java.util.jar.JarInputStream;
import java.util.jar.JarOutputStream;
import java.util.jar.Manifest;
import java.util.regex.Matcher;
import java.util.regex.Pattern;
import java.util.stream.Stream;

/**
 * Every door through which code can reach a running runtime, tried as an attacker on the same
 * machine would (issue 16 finding 3, docs/DECISIONS.md D12): Felix's own {@code install} and
 * {@code update} with http, file, reference: and jar: URLs, a bundle's
 * {@code Bundle-UpdateLocation}, our {@code update} and {@code deploy} without or with a wrong
 * pin, a truncated jar and one with an extra entry. The attacker's jar is the sample counter
 * with one more entry: it would run if admitted. An attempt <em>succeeded</em> when the code
 * gate admitted the attacker's content or the component became ACTIVE (with a new process, for
 * an update of a running one). Two controls show that the check can see a success: the counter
 * from the runtime's own {@code tools/} folder, and an update with the right pinned SHA-256.
 * Used by {@link CodeDoorsIT} (the doors must stay shut) and the attack benchmark.
 */
final class CodeDoors implements AutoCloseable {

    static final String COMPONENT = "sample-counter";
    private static final Pattern BUNDLE_ID = Pattern.compile("Bundle ID: (\\d+)");

    /** One try at a door: whether it got code running, and what the runtime said. */
    record Attempt(String door, boolean succeeded, String detail) {
    }

    private final Runtime rt;
    private final Path trusted;
    private final Path outside;
    private final Path evil;
    private final HttpServer http;
    private final Map<String, byte[]> served = new ConcurrentHashMap<>();
    final List<Attempt> attempts = new ArrayList<>();
    final List<String> controls = new ArrayList<>();

    /**
     * @param rt a runtime whose code gate trusts only its own folders
     * @param outside a folder outside them, for the attacker's files
     */
    CodeDoors(Runtime rt, Path outside) throws IOException {
        this.rt = rt;
        Runtime.deleteTree(outside); // what an earlier run left
        this.outside = Files.createDirectories(outside);
        Path counter = Components.jar("sample-counter");
        this.trusted = Files.copy(counter, Files.createDirectories(rt.dir.resolve("tools")).resolve("counter.jar"));
        this.evil = withExtraEntry(counter, outside.resolve("evil.jar"), null);
        http = HttpServer.create(new InetSocketAddress("127.0.0.1", 0), 0);
        http.createContext("/", ex -> {
            byte[] b = served.get(ex.getRequestURI().getPath());
            if (b == null) {
                ex.sendResponseHeaders(404, -1);
            } else {
                ex.sendResponseHeaders(200, b.length);
                try (OutputStream o = ex.getResponseBody()) {
                    o.write(b);
                }
            }
            ex.close();
        });
        http.start();
        served.put("/evil.jar", Files.readAllBytes(evil));
    }

    String url(String path) {
        return "http://127.0.0.1:" + http.getAddress().getPort() + path;
    }

    /** Tries every door that answers quickly. */
    void tryAll() throws Exception {
        control();
        freshInstall("felix install http://", "install " + url("/evil.jar"));
        freshInstall("felix install file: outside the trusted folders", "install " + evil.toUri());
        freshInstall("felix install reference:file:", "install reference:" + evil.toUri());
        Path outer = outside.resolve("outer.zip");
        try (OutputStream o = Files.newOutputStream(outer); JarOutputStream z = new JarOutputStream(o)) {
            z.putNextEntry(new JarEntry("evil.jar"));
            z.write(Files.readAllBytes(evil));
            z.closeEntry();
        }
        freshInstall("felix install jar:file:...!/", "install jar:" + outer.toUri() + "!/evil.jar");
        update("felix update <id> http://", id -> "felix:update " + id + " " + url("/evil.jar"));
        update("felix update <id> file: outside", id -> "felix:update " + id + " " + evil.toUri());
        update("felix update <id> jar:file:...!/", id -> "felix:update " + id + " jar:" + outer.toUri() + "!/evil.jar");
        update("update <id> http://", id -> "update " + id + " " + url("/evil.jar"));
        update("update <id> file: (no pin)", id -> "update " + id + " " + evil.toUri());
        update("update <id> jar:file:...!/", id -> "update " + id + " jar:" + outer.toUri() + "!/evil.jar");
        update("update <id> <url> <wrong sha256>", id -> "update " + id + " " + evil.toUri() + " " + "0".repeat(64));
        Path truncated = outside.resolve("truncated.jar");
        byte[] whole = Files.readAllBytes(evil);
        Files.write(truncated, java.util.Arrays.copyOf(whole, whole.length / 2));
        freshInstall("deploy truncated jar, pin of the whole", "arflex:deploy " + truncated.toUri() + " " + Jars.sha256(evil));
        Path extra = withExtraEntry(evil, outside.resolve("extra.jar"), null);
        freshInstall("deploy jar with an extra entry, pin of the original",
                "arflex:deploy " + extra.toUri() + " " + Jars.sha256(evil));
        freshInstall("deploy http:// with its right pin", "arflex:deploy " + url("/evil.jar") + " " + Jars.sha256(evil));
        // A bundle from the trusted folder whose manifest says where its updates come from.
        Path withUl = withExtraEntry(Components.jar("sample-counter"),
                rt.dir.resolve("tools/counter-ul.jar"), url("/evil.jar"));
        updateOf(withUl, "felix update <id> (Bundle-UpdateLocation: http://)", id -> "felix:update " + id);
        updateOf(withUl, "update <id> (Bundle-UpdateLocation: http://)", id -> "update " + id);
        signatures();
    }

    /**
     * Signed code (D14): a jar signed by a key the runtime trusts runs from anywhere (a control);
     * one signed by an unknown key, and a trusted-signed one with an entry added afterwards, do not.
     */
    private void signatures() throws Exception {
        Path keys = Files.createDirectories(outside.resolve("keys"));
        Path trustedKs = keys.resolve("trusted.p12");
        Path unknownKs = keys.resolve("unknown.p12");
        jdk("keytool", "-genkeypair", "-alias", "k", "-keyalg", "EC", "-groupname", "secp256r1", "-validity", "30",
                "-dname", "CN=ARFLEX test integrator", "-keystore", trustedKs.toString(), "-storetype", "PKCS12",
                "-storepass", "changeit-test");
        jdk("keytool", "-genkeypair", "-alias", "k", "-keyalg", "EC", "-groupname", "secp256r1", "-validity", "30",
                "-dname", "CN=Somebody else", "-keystore", unknownKs.toString(), "-storetype", "PKCS12",
                "-storepass", "changeit-test");
        Path trustDir = Files.createDirectories(rt.dir.resolve("trust"));
        Files.setPosixFilePermissions(trustDir, java.nio.file.attribute.PosixFilePermissions.fromString("rwxr-xr-x"));
        jdk("keytool", "-exportcert", "-rfc", "-alias", "k", "-keystore", trustedKs.toString(), "-storetype", "PKCS12",
                "-storepass", "changeit-test", "-file", trustDir.resolve("integrator.crt").toString());
        Files.setPosixFilePermissions(trustDir.resolve("integrator.crt"),
                java.nio.file.attribute.PosixFilePermissions.fromString("rw-r--r--"));
        Path signedTrusted = Files.copy(evil, outside.resolve("signed-trusted.jar"));
        jdk("jarsigner", "-keystore", trustedKs.toString(), "-storetype", "PKCS12", "-storepass", "changeit-test",
                "-digestalg", "SHA-256", signedTrusted.toString(), "k");
        Path signedUnknown = Files.copy(evil, outside.resolve("signed-unknown.jar"));
        jdk("jarsigner", "-keystore", unknownKs.toString(), "-storetype", "PKCS12", "-storepass", "changeit-test",
                "-digestalg", "SHA-256", signedUnknown.toString(), "k");
        Path tampered = withExtraEntry(signedTrusted, outside.resolve("signed-tampered.jar"), null);

        int mark = rt.logMark();
        String out = rt.cmd("install " + signedTrusted.toUri());
        Matcher m = BUNDLE_ID.matcher(out);
        if (!m.find()) {
            throw new AssertionError("control failed: a trusted-signed jar was not installed: " + out);
        }
        long id = Long.parseLong(m.group(1));
        Attempt control = judge("control", id, mark, 0, rt.cmd("start " + id), true);
        if (!control.succeeded()) {
            throw new AssertionError("control failed: a jar signed by a trusted key did not run (" + control.detail() + ")\n"
                    + rt.tail());
        }
        controls.add("jar signed by a key of the trust store, from outside the trusted folders: admitted, ACTIVE");
        rt.cmd("uninstall " + id);
        rt.waitUntil(COMPONENT + " gone", CellIT.T, () -> rt.instance(COMPONENT) == null);
        freshInstall("felix install of a jar signed by an unknown key", "install " + signedUnknown.toUri());
        freshInstall("felix install of a trusted-signed jar with an entry added", "install " + tampered.toUri());
        freshInstall("deploy (no pin) of a jar signed by an unknown key", "arflex:deploy " + signedUnknown.toUri());
    }

    /** Runs a JDK tool (keytool, jarsigner) of this JVM, failing with its output. */
    static void jdk(String tool, String... args) throws Exception {
        List<String> cmd = new ArrayList<>();
        cmd.add(Path.of(System.getProperty("java.home"), "bin", tool).toString());
        cmd.addAll(List.of(args));
        Process p = new ProcessBuilder(cmd).redirectErrorStream(true).start();
        String out = new String(p.getInputStream().readAllBytes(), StandardCharsets.UTF_8);
        if (p.waitFor() != 0) {
            throw new AssertionError(tool + " failed: " + out);
        }
    }

    /**
     * Felix's update from a server that accepts and never answers: the shell must come back
     * (finding 4). Slow (the read timeout), so for the benchmark only.
     */
    void trySilentServer() throws Exception {
        try (ServerSocket silent = new ServerSocket(0, 50, java.net.InetAddress.getByName("127.0.0.1"))) {
            List<Socket> held = new ArrayList<>();
            Thread acceptor = new Thread(() -> {
                while (!silent.isClosed()) {
                    try {
                        held.add(silent.accept());
                    } catch (IOException e) {
                        return;
                    }
                }
            }, "silent-server");
            acceptor.setDaemon(true);
            acceptor.start();
            for (String scheme : new String[] {"ftp", "http"}) {
                long id = rt.install(trusted);
                String u = scheme + "://127.0.0.1:" + silent.getLocalPort() + "/x.jar";
                long t0 = System.nanoTime();
                String out;
                boolean blocked = false;
                try {
                    out = rt.cmd("felix:update " + id + " " + u);
                } catch (AssertionError e) {
                    out = "no reply within 60 s";
                    blocked = true;
                }
                double s = (System.nanoTime() - t0) / 1e9;
                attempts.add(new Attempt("felix update <id> " + scheme + ":// that never answers", blocked,
                        String.format(java.util.Locale.ROOT, "shell back after %.1f s: %s", s, firstLine(out))));
                if (blocked) {
                    break; // the shell is stuck: nothing further can be tried through it
                }
                rt.cmd("uninstall " + id);
            }
            for (Socket s : held) {
                s.close();
            }
        }
    }

    /**
     * Finding 5: started under umask 000, is anything on the way to a native executable writable
     * by others, and does an executable replaced on disk run at the next restart?
     */
    static Attempt umask000(Path work) throws Exception {
        String door = "umask 000: writable cache, replaced RT executable";
        try (Runtime rt = new Runtime("attack-umask", null, true, "bundle,cell,tools", "000")) {
            Path jar = Files.copy(Components.jar("sample-counter"),
                    Files.createDirectories(rt.dir.resolve("tools")).resolve("counter.jar"));
            long id = rt.installAndStart(jar);
            rt.awaitState("ACTIVE", CellIT.T, COMPONENT);
            long pid = rt.pid(COMPONENT);
            Path exe = Path.of("/proc/" + pid + "/exe").toRealPath();
            List<String> writable = new ArrayList<>();
            for (Path p = exe; p != null && p.startsWith(rt.dir); p = p.getParent()) {
                if (othersMayWrite(p)) {
                    writable.add(p.toString());
                }
            }
            try (Stream<Path> s = Files.walk(rt.dir.resolve("felix-cache"))) {
                s.filter(CodeDoors::othersMayWriteQuietly).limit(5).forEach(p -> writable.add(p.toString()));
            }
            // The attacker (here with the rights to do so) replaces the executable, then the half dies.
            Path marker = work.resolve("attack-umask-pwned");
            Files.deleteIfExists(marker);
            // (a running executable cannot be written: it is replaced by a rename, as an attacker would)
            Path fake = exe.resolveSibling(exe.getFileName() + ".new");
            Files.writeString(fake, "#!/bin/sh\ntouch '" + marker + "'\nexec sleep 30\n", StandardCharsets.UTF_8);
            Files.setPosixFilePermissions(fake, Set.of(PosixFilePermission.OWNER_READ, PosixFilePermission.OWNER_WRITE,
                    PosixFilePermission.OWNER_EXECUTE));
            Files.move(fake, exe, java.nio.file.StandardCopyOption.REPLACE_EXISTING, java.nio.file.StandardCopyOption.ATOMIC_MOVE);
            FailSafeIT.kill9(pid);
            boolean back;
            try {
                rt.waitUntil("the counter restarted", CellIT.T, () -> rt.activeWithNewPid(COMPONENT, pid));
                back = true;
            } catch (AssertionError e) {
                back = false;
            }
            boolean ran = Files.exists(marker);
            rt.cmd("uninstall " + id);
            rt.waitUntil(COMPONENT + " gone", CellIT.T, () -> rt.instance(COMPONENT) == null);
            Files.deleteIfExists(marker);
            return new Attempt(door, ran || !writable.isEmpty(),
                    (writable.isEmpty() ? "nothing writable by others" : "writable by others: " + writable)
                            + (ran ? "; the replaced executable RAN" : "; the replaced executable did not run")
                            + (back ? ", the counter came back verified" : ", the counter did not come back"));
        }
    }

    private static boolean othersMayWrite(Path p) throws IOException {
        Set<PosixFilePermission> s = Files.getPosixFilePermissions(p, java.nio.file.LinkOption.NOFOLLOW_LINKS);
        return s.contains(PosixFilePermission.GROUP_WRITE) || s.contains(PosixFilePermission.OTHERS_WRITE);
    }

    private static boolean othersMayWriteQuietly(Path p) {
        try {
            return !Files.isSymbolicLink(p) && othersMayWrite(p);
        } catch (IOException e) {
            return false;
        }
    }

    /** The controls: the checker sees code that runs. */
    private void control() throws Exception {
        long id = rt.installAndStart(trusted);
        rt.awaitState("ACTIVE", CellIT.T, COMPONENT);
        controls.add("counter from tools/: ACTIVE (bundle " + id + ")");
        long pid = rt.pid(COMPONENT);
        int mark = rt.logMark();
        Path pinned = withExtraEntry(trusted, outside.resolve("pinned.jar"), null);
        String out = rt.cmd("update " + id + " " + pinned.toUri() + " " + Jars.sha256(pinned));
        Attempt a = judge("control", id, mark, pid, out, true);
        if (!a.succeeded()) {
            throw new AssertionError("control failed: a pinned update did not run (" + a.detail() + ")\n" + rt.tail());
        }
        controls.add("update with the right pinned SHA-256: admitted, ACTIVE with a new process");
        rt.cmd("uninstall " + id);
        rt.waitUntil(COMPONENT + " gone", CellIT.T, () -> rt.instance(COMPONENT) == null);
    }

    private void freshInstall(String door, String command) {
        int mark = rt.logMark();
        String out = rt.cmd(command);
        Matcher m = BUNDLE_ID.matcher(out);
        if (!m.find()) {
            attempts.add(new Attempt(door, false, "not installed: " + firstLine(out)));
            return;
        }
        long id = Long.parseLong(m.group(1));
        String started = rt.cmd("start " + id);
        Attempt a = judge(door, id, mark, 0, started.isEmpty() ? "" : started, true);
        // Java code: the gate keeps the bundle from resolving, so it cannot be ACTIVE (32)
        String state = rt.cmd("(bundle " + id + ") state").strip();
        boolean javaRuns = state.equals("32") || state.equals("8") || state.equals("4");
        a = new Attempt(a.door(), a.succeeded() || javaRuns, a.detail() + "; bundle state " + state
                + (javaRuns ? " (resolved: its Java code can run)" : " (INSTALLED: not resolved, no code of it runs)"));
        attempts.add(a);
        rt.cmd("uninstall " + id);
        rt.waitUntil(COMPONENT + " gone", CellIT.T, () -> rt.instance(COMPONENT) == null);
    }

    interface Command {
        String of(long id);
    }

    private void update(String door, Command command) throws Exception {
        updateOf(trusted, door, command);
    }

    /** Installs {@code base} (trusted), lets it run, then tries {@code command} on it. */
    private void updateOf(Path base, String door, Command command) throws Exception {
        long id = rt.installAndStart(base);
        rt.awaitState("ACTIVE", CellIT.T, COMPONENT);
        long pid = rt.pid(COMPONENT);
        int mark = rt.logMark();
        String out = rt.cmd(command.of(id));
        // the transport took the jar when Felix says nothing, or that the gate's hook kept it from resolving
        attempts.add(judge(door, id, mark, pid, out, out.isEmpty() || out.contains("Resolver hook prevented resolution")));
        rt.cmd("uninstall " + id);
        rt.waitUntil(COMPONENT + " gone", CellIT.T, () -> rt.instance(COMPONENT) == null);
    }

    /**
     * Whether bundle {@code id} runs the attacker's code: waits for the gate's decision when the
     * transport took the jar ({@code took}), then looks at the log and the instance.
     */
    private Attempt judge(String door, long id, int mark, long oldPid, String out, boolean took) {
        String tag = "code gate: bundle " + id + " ";
        if (took) {
            try {
                rt.waitUntil("the code gate's decision on bundle " + id, 20_000,
                        () -> rt.logSince(mark).stream().anyMatch(l -> l.contains(tag)));
            } catch (AssertionError e) {
                // no decision: judged by the instance below
            }
        }
        String decision = rt.logSince(mark).stream().filter(l -> l.contains(tag)).reduce((a, b) -> b).orElse("");
        Map<String, Object> inst = rt.instance(COMPONENT);
        boolean active = inst != null && "ACTIVE".equals(inst.get("state"))
                && ((Number) inst.get("pid")).longValue() != 0 && ((Number) inst.get("pid")).longValue() != oldPid;
        boolean admitted = decision.contains(tag + "admitted");
        String why = !decision.isEmpty() ? decision.substring(decision.indexOf(tag))
                : !out.isEmpty() ? firstLine(out) : "no decision, " + (inst == null ? "no instance" : inst.get("state"));
        return new Attempt(door, admitted || active, why);
    }

    private static String firstLine(String s) {
        String l = s.strip().lines().findFirst().orElse("");
        return l.length() > 160 ? l.substring(0, 160) + "..." : l;
    }

    /** A copy of {@code jar} with one more entry, and a Bundle-UpdateLocation when given. */
    static Path withExtraEntry(Path jar, Path out, String updateLocation) throws IOException {
        try (InputStream fin = Files.newInputStream(jar); JarInputStream in = new JarInputStream(fin)) {
            Manifest m = new Manifest(in.getManifest());
            if (updateLocation != null) {
                m.getMainAttributes().put(new Attributes.Name("Bundle-UpdateLocation"), updateLocation);
            }
            try (OutputStream fout = Files.newOutputStream(out); JarOutputStream o = new JarOutputStream(fout, m)) {
                JarEntry e;
                while ((e = in.getNextJarEntry()) != null) {
                    o.putNextEntry(new JarEntry(e.getName()));
                    o.write(in.readAllBytes());
                    o.closeEntry();
                }
                o.putNextEntry(new JarEntry("extra-" + out.getFileName() + ".txt"));
                o.write(("added to " + jar.getFileName()).getBytes(StandardCharsets.UTF_8));
                o.closeEntry();
            }
        }
        return out;
    }

    @Override
    public void close() {
        http.stop(0);
    }
}
