package org.arflex.webconsole;

import java.io.IOException;
import java.io.OutputStream;
import java.net.ServerSocket;
import java.net.URI;
import java.net.http.HttpClient;
import java.net.http.HttpRequest;
import java.net.http.HttpResponse;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.nio.file.StandardCopyOption;
import java.security.SecureRandom;
import java.time.Duration;
import java.util.Base64;
import java.util.Comparator;
import java.util.List;
import java.util.Optional;
import java.util.concurrent.TimeUnit;
import java.util.function.BooleanSupplier;
import java.util.stream.Stream;

/**
 * The assembled ARFLEX runtime started as a child process through scripts/run-cell.sh, with a
 * fresh ARFLEX_HOME, a random console password and a free HTTP port, from a private copy of
 * management/runtime/target/arflex-runtime with this module's bundle added to console/.
 */
final class RuntimeUnderTest implements AutoCloseable {
    static final String USER = "arflex";
    /** The folder under {@link #work} the console accepts file: update jars from (its staging rule, D78). */
    static final String STAGED = "staged";
    final String password;
    final int port;
    final Path work;
    final Path runtimeDir;
    final Path home;
    final Path log;
    private final Process process;
    private final OutputStream stdin;
    private HttpClient http = HttpClient.newBuilder().connectTimeout(Duration.ofSeconds(5)).build();
    /** The HTTPS port when the console was started with TLS (ARFLEX_CONSOLE_TLS), else 0. */
    final int tlsPort;
    private boolean tlsClient;

    RuntimeUnderTest(Path work) throws IOException {
        this(work, false);
    }

    /** @param tls serve the console over HTTPS only (ARFLEX_CONSOLE_TLS=true, a generated key) */
    RuntimeUnderTest(Path work, boolean tls) throws IOException {
        this(work, tls, java.util.Map.of());
    }

    /** @param sysprops JVM system properties that replace the assembly's (conf/system.properties) */
    RuntimeUnderTest(Path work, boolean tls, java.util.Map<String, String> sysprops) throws IOException {
        Path assembled = Path.of(System.getProperty("arflex.runtime.dir",
                "../management/runtime/target/arflex-runtime")).toAbsolutePath().normalize();
        Path jar = Path.of(System.getProperty("arflex.webconsole.jar", "target/org.arflex.webconsole.jar"));
        Path root = Path.of(System.getProperty("arflex.root", "..")).toAbsolutePath().normalize();
        if (!Files.isRegularFile(assembled.resolve("bin/felix.jar"))) {
            throw new IllegalStateException("no assembled runtime at " + assembled
                    + " (build it: mvn -Darflex.native.skip=true -DskipTests -pl management/runtime package)");
        }
        if (!Files.isRegularFile(jar)) {
            throw new IllegalStateException("no web console bundle at " + jar + " (run the package phase first)");
        }
        this.work = work;
        deleteTree(work);
        this.runtimeDir = work.resolve("runtime");
        this.home = work.resolve("home");
        this.log = work.resolve("runtime.log");
        // No bundle cache of the assembly's, and no demonstration cell (the tests install their
        // own components through the console): neither is copied (D67: one runtime per test class).
        copyTree(assembled, runtimeDir, List.of("felix-cache", "cell"));
        Files.writeString(runtimeDir.resolve("conf/cell.gosh"), "# the browser tests install their own components\n");
        // The freshly built console bundle replaces any copy the assembly already carries.
        for (String dir : List.of("bundle", "console")) {
            try (Stream<Path> s = Files.list(runtimeDir.resolve(dir))) {
                for (Path p : s.filter(p -> p.getFileName().toString().startsWith("org.arflex.webconsole")).toList()) {
                    Files.delete(p);
                }
            }
        }
        Files.copy(jar, runtimeDir.resolve("console/org.arflex.webconsole.jar"));
        // The debug monitor the console installs from its Debug page: where the assembly ships it
        // (tools/), from the freshly built bundle when the assembly does not carry one yet.
        Path tools = Files.createDirectories(runtimeDir.resolve("tools"));
        String debugmon = org.arflex.it.Components.jar("debug-monitor").toString();
        boolean shipped;
        try (Stream<Path> s = Files.list(tools)) {
            shipped = s.anyMatch(p -> p.getFileName().toString().startsWith("org.arflex.debug.monitor"));
        }
        if (!shipped && debugmon != null && Files.isRegularFile(Path.of(debugmon))) {
            Files.copy(Path.of(debugmon), tools.resolve("org.arflex.debug.monitor.jar"));
        }
        this.port = freePort();
        this.tlsPort = tls ? freePort() : 0;
        Path conf = runtimeDir.resolve("conf/config.properties");
        String props = Files.readString(conf).replaceAll("(?m)^org\\.osgi\\.service\\.http\\.port=.*$",
                "org.osgi.service.http.port=" + port);
        // stage-url and the change-set page's update lines read file: URLs only from configured
        // folders (D78): those of the sample bundles, and work/staged, where a test puts the
        // versions it makes, as an operator puts update jars in a staging folder
        String stageDirs = String.join(",", Stream.concat(Stream.of("counter", "scaler")
                .map(w -> org.arflex.it.Components.jar("sample-" + w).getParent().toString()),
                Stream.of(work.resolve(STAGED).toString())).distinct().toList());
        props += "\narflex.console.stage.dirs=" + stageDirs + "\n";
        // The tests install cell bundles from the assembly they were copied from and from the
        // build: the code gate (D12) trusts those folders as it trusts the runtime's own.
        // The jars the browser tests make for themselves (work/jars) are trusted too: they test
        // the console's defences behind the gate, not the gate.
        props += "arflex.code.trusted=bundle,cell,tools,console," + assembled.resolve("cell") + "," + root.resolve("bundles")
                + "," + work.resolve("jars") + "\n";
        Files.writeString(conf, props);
        if (!sysprops.isEmpty()) {
            StringBuilder sp = new StringBuilder();
            sysprops.forEach((k, v) -> sp.append(k).append('=').append(v).append('\n'));
            Files.writeString(runtimeDir.resolve("conf/system.properties"), sp.toString());
        }
        byte[] pw = new byte[18];
        new SecureRandom().nextBytes(pw);
        this.password = Base64.getUrlEncoder().withoutPadding().encodeToString(pw);

        ProcessBuilder pb = new ProcessBuilder("bash", root.resolve("scripts/run-cell.sh").toString(),
                runtimeDir.toString());
        pb.environment().put("ARFLEX_HOME", home.toString());
        pb.environment().put("ARFLEX_CONSOLE_USER", USER);
        pb.environment().put("ARFLEX_CONSOLE_PASSWORD", password);
        if (tls) {
            pb.environment().put("ARFLEX_CONSOLE_TLS", "true");
            pb.environment().put("ARFLEX_CONSOLE_HTTPS_PORT", Integer.toString(tlsPort));
        }
        pb.redirectErrorStream(true).redirectOutput(log.toFile());
        pb.directory(runtimeDir.toFile());
        this.process = pb.start();
        this.stdin = process.getOutputStream();
    }

    /** Waits until the console answers and the DRCR is registered. */
    void awaitUp(Duration timeout) {
        awaitCondition("the console at port " + port + " and the DRCR up", timeout, () -> {
            if (!process.isAlive()) {
                throw new IllegalStateException("the runtime exited early; log:\n" + tail());
            }
            HttpResponse<String> r = get("/system/console/arflex-cell/api/cell", true);
            return r != null && r.statusCode() == 200 && r.body().contains("\"drcr\":true");
        });
    }

    /** A plain-HTTP base on the configured port (for checking that it is off under TLS). */
    String plainBase() {
        return "http://127.0.0.1:" + port;
    }

    String base() {
        if (tlsPort != 0) {
            return "https://127.0.0.1:" + tlsPort;
        }
        return "http://127.0.0.1:" + port;
    }

    String basicAuth() {
        return "Basic " + Base64.getEncoder().encodeToString((USER + ":" + password).getBytes(StandardCharsets.UTF_8));
    }

    /** GET with or without the console credentials; null when the server does not answer. */
    HttpResponse<String> get(String path, boolean auth) {
        return send(HttpRequest.newBuilder(URI.create(base() + path)).GET(), auth);
    }

    HttpResponse<String> send(HttpRequest.Builder b, boolean auth) {
        if (auth) {
            b.header("Authorization", basicAuth());
        }
        try {
            return client().send(b.timeout(Duration.ofSeconds(10)).build(), HttpResponse.BodyHandlers.ofString());
        } catch (IOException e) {
            return null;
        } catch (InterruptedException e) {
            Thread.currentThread().interrupt();
            throw new IllegalStateException(e);
        }
    }

    /**
     * The client; under TLS one that trusts exactly the certificate run-cell.sh generated in the
     * home (once it exists), as an operator who checked its fingerprint would.
     */
    private HttpClient client() {
        Path ks = home.resolve("console-tls.p12");
        if (tlsPort != 0 && !tlsClient && Files.isRegularFile(ks) && Files.isRegularFile(home.resolve("console-tls.pass"))) {
            try {
                char[] pw = Files.readString(home.resolve("console-tls.pass")).toCharArray();
                java.security.KeyStore store = java.security.KeyStore.getInstance("PKCS12");
                try (var in = Files.newInputStream(ks)) {
                    store.load(in, pw);
                }
                java.security.KeyStore trust = java.security.KeyStore.getInstance("PKCS12");
                trust.load(null, null);
                trust.setCertificateEntry("console", store.getCertificate("console"));
                javax.net.ssl.TrustManagerFactory tmf = javax.net.ssl.TrustManagerFactory.getInstance(
                        javax.net.ssl.TrustManagerFactory.getDefaultAlgorithm());
                tmf.init(trust);
                javax.net.ssl.SSLContext ctx = javax.net.ssl.SSLContext.getInstance("TLS");
                ctx.init(null, tmf.getTrustManagers(), null);
                http = HttpClient.newBuilder().connectTimeout(Duration.ofSeconds(5)).sslContext(ctx).build();
                tlsClient = true;
            } catch (IOException | java.security.GeneralSecurityException e) {
                // not written completely yet: the next call tries again
            }
        }
        return http;
    }

    /** Sends a Gogo command line to the runtime's shell. */
    void gogo(String line) throws IOException {
        stdin.write((line + "\n").getBytes(StandardCharsets.UTF_8));
        stdin.flush();
    }

    String tail() {
        try {
            List<String> lines = Files.readAllLines(log);
            return String.join("\n", lines.subList(Math.max(0, lines.size() - 60), lines.size()));
        } catch (IOException e) {
            return "(no log: " + e.getMessage() + ")";
        }
    }

    /**
     * Nothing leaks once a runtime is closed: no child process of this JVM (waited for, 20 s),
     * no /dev/shm or /dev/mqueue object of runtime {@code runtimeId} (null: its id was never read).
     */
    static void assertNothingLeft(String runtimeId) throws IOException {
        awaitCondition("child processes to end", Duration.ofSeconds(20),
                () -> ProcessHandle.current().descendants().noneMatch(ProcessHandle::isAlive));
        if (runtimeId == null) {
            return;
        }
        String prefix = "arflex." + runtimeId + ".";
        for (String dir : List.of("/dev/shm", "/dev/mqueue")) {
            Path d = Path.of(dir);
            if (Files.isDirectory(d)) {
                try (Stream<Path> s = Files.list(d)) {
                    List<Path> left = s.filter(p -> p.getFileName().toString().startsWith(prefix)).toList();
                    org.junit.jupiter.api.Assertions.assertTrue(left.isEmpty(), "left over in " + dir + ": " + left);
                }
            }
        }
    }

    /**
     * The runtime JVM's threads ({@code jcmd <pid> Thread.print}), for a test that waited in
     * vain for the console's answer: what the request's thread was blocked on.
     */
    String threadDump() {
        Optional<ProcessHandle> jvm = process.descendants()
                .filter(p -> p.info().command().map(c -> c.endsWith("/java")).orElse(false)).findFirst();
        if (jvm.isEmpty()) {
            return "(no runtime JVM found under " + process.pid() + ")";
        }
        try {
            Process j = new ProcessBuilder("jcmd", String.valueOf(jvm.get().pid()), "Thread.print").redirectErrorStream(true)
                    .start();
            String out = new String(j.getInputStream().readAllBytes(), java.nio.charset.StandardCharsets.UTF_8);
            j.waitFor(30, TimeUnit.SECONDS);
            return out;
        } catch (IOException e) {
            return "(jcmd failed: " + e + ")";
        } catch (InterruptedException e) {
            Thread.currentThread().interrupt();
            return "(interrupted)";
        }
    }

    /** Stops the framework through Gogo; kills what is left after the deadline. */
    @Override
    public void close() throws IOException {
        try {
            gogo("stop 0");
            stdin.close();
        } catch (IOException e) {
            // already gone
        }
        try {
            if (!process.waitFor(60, TimeUnit.SECONDS)) {
                process.descendants().forEach(ProcessHandle::destroyForcibly);
                process.destroyForcibly();
                process.waitFor(10, TimeUnit.SECONDS);
            }
        } catch (InterruptedException e) {
            Thread.currentThread().interrupt();
        }
    }

    static void awaitCondition(String what, Duration timeout, BooleanSupplier condition) {
        long deadline = System.nanoTime() + timeout.toNanos();
        while (!condition.getAsBoolean()) {
            if (System.nanoTime() > deadline) {
                throw new AssertionError("timed out after " + timeout.toSeconds() + " s waiting for " + what);
            }
            try {
                Thread.sleep(100);
            } catch (InterruptedException e) {
                Thread.currentThread().interrupt();
                throw new AssertionError("interrupted waiting for " + what);
            }
        }
    }

    private static int freePort() throws IOException {
        try (ServerSocket s = new ServerSocket(0)) {
            return s.getLocalPort();
        }
    }

    /** Copies {@code from} to {@code to} but for the top-level entries named in {@code leftOut}. */
    private static void copyTree(Path from, Path to, List<String> leftOut) throws IOException {
        try (Stream<Path> s = Files.walk(from)) {
            for (Path p : s.filter(p -> p.equals(from) || !leftOut.contains(from.relativize(p).getName(0).toString())).toList()) {
                Path t = to.resolve(from.relativize(p).toString());
                if (Files.isDirectory(p)) {
                    Files.createDirectories(t);
                } else {
                    Files.copy(p, t, StandardCopyOption.COPY_ATTRIBUTES);
                }
            }
        }
    }

    static void deleteTree(Path p) throws IOException {
        if (!Files.exists(p)) {
            return;
        }
        try (Stream<Path> s = Files.walk(p)) {
            for (Path q : s.sorted(Comparator.reverseOrder()).toList()) {
                Files.delete(q);
            }
        }
    }
}
