package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertNotEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;
import static org.junit.jupiter.api.Assertions.fail;

import java.io.BufferedReader;
import java.io.IOException;
import java.io.InputStreamReader;
import java.net.ConnectException;
import java.net.HttpURLConnection;
import java.net.Inet4Address;
import java.net.InetAddress;
import java.net.InetSocketAddress;
import java.net.NetworkInterface;
import java.net.Socket;
import java.net.URI;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.nio.file.attribute.PosixFilePermissions;
import java.security.MessageDigest;
import java.util.ArrayList;
import java.util.Base64;
import java.util.List;
import java.util.Map;
import java.util.concurrent.CopyOnWriteArrayList;
import java.util.concurrent.TimeUnit;
import java.util.function.BooleanSupplier;
import java.util.regex.Matcher;
import java.util.regex.Pattern;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;

/**
 * The main job as the README runs it ({@code ./arflex run --headless N} is
 * {@code scripts/run-cell.sh <runtime> N} after the build), and its console login
 * ({@code scripts/console-login.sh}): no default password, a generated one printed once and
 * kept only as a hash in a private file, the console on the loopback interface only. The job
 * waits through the DRCR's {@code arflex:await} and prints {@code arflex:summary}'s line
 * (docs/DECISIONS.md D31); it keeps no log of the runtime.
 */
class MainJobIT {

    static final Path ROOT = Path.of(System.getProperty("arflex.root", "."));
    static final Pattern PASSWORD = Pattern.compile("arflex: {3}user (\\S+), password (\\S+)");
    static final long T = 120_000;

    record Run(int exit, List<String> lines) {
        String text() {
            return String.join("\n", lines);
        }
    }

    static Run login(Path home, Map<String, String> env) throws Exception {
        ProcessBuilder pb = new ProcessBuilder("bash", ROOT.resolve("scripts/console-login.sh").toString(), home.toString())
                .redirectErrorStream(true);
        pb.environment().remove("ARFLEX_CONSOLE_PASSWORD");
        pb.environment().remove("ARFLEX_CONSOLE_USER");
        pb.environment().putAll(env);
        Process p = pb.start();
        String out = new String(p.getInputStream().readAllBytes(), StandardCharsets.UTF_8);
        assertTrue(p.waitFor(30, TimeUnit.SECONDS), "console-login.sh did not end");
        return new Run(p.exitValue(), out.lines().toList());
    }

    static final Pattern PBKDF2 = Pattern.compile("arflex\\.console\\.password=\\{pbkdf2-sha256\\}(\\d+)\\$([A-Za-z0-9+/=]+)\\$([A-Za-z0-9+/=]+)");

    /** Whether {@code stored} (a credentials file) holds {@code password} as a salted PBKDF2 hash (D81). */
    static boolean holdsPbkdf2Of(String stored, String password) throws Exception {
        Matcher m = PBKDF2.matcher(stored);
        if (!m.find()) {
            return false;
        }
        byte[] salt = Base64.getDecoder().decode(m.group(2));
        byte[] want = Base64.getDecoder().decode(m.group(3));
        javax.crypto.spec.PBEKeySpec spec = new javax.crypto.spec.PBEKeySpec(password.toCharArray(), salt,
                Integer.parseInt(m.group(1)), 256);
        byte[] got = javax.crypto.SecretKeyFactory.getInstance("PBKDF2WithHmacSHA256").generateSecret(spec).getEncoded();
        return salt.length >= 16 && Integer.parseInt(m.group(1)) >= 100_000 && MessageDigest.isEqual(want, got);
    }

    @Test
    void theConsoleLoginIsGeneratedOnceKeptAsAHashInAPrivateFile(@TempDir Path tmp) throws Exception {
        Path home = tmp.resolve("home");
        Run first = login(home, Map.of());
        assertEquals(0, first.exit(), first.text());
        Matcher m = PASSWORD.matcher(first.text());
        assertTrue(m.find(), "no generated password printed: " + first.text());
        String password = m.group(2);
        assertTrue(password.length() >= 20, "a short password: " + password.length() + " characters");
        Path creds = home.resolve("console.properties");
        assertEquals(creds.toString(), first.lines().get(first.lines().size() - 1));
        assertEquals("rw-------", PosixFilePermissions.toString(Files.getPosixFilePermissions(creds)));
        assertEquals("rwx------", PosixFilePermissions.toString(Files.getPosixFilePermissions(home)));
        String stored = Files.readString(creds);
        assertFalse(stored.contains(password), "the password itself is stored");
        assertTrue(holdsPbkdf2Of(stored, password), stored);
        assertTrue(stored.contains("arflex.console.username=arflex"), stored);

        // Second start: nothing printed, nothing changed.
        Run second = login(home, Map.of());
        assertEquals(0, second.exit(), second.text());
        assertFalse(second.text().contains("password"), "printed again: " + second.text());
        assertEquals(stored, Files.readString(creds));

        // Set by the environment: a private temporary file of that login; the generated one stays.
        Run set = login(home, Map.of("ARFLEX_CONSOLE_USER", "integrator", "ARFLEX_CONSOLE_PASSWORD", "s3cret-Pass"));
        assertEquals(0, set.exit(), set.text());
        Path tmpCreds = Path.of(set.lines().get(set.lines().size() - 1));
        assertNotEquals(creds, tmpCreds);
        assertEquals("rw-------", PosixFilePermissions.toString(Files.getPosixFilePermissions(tmpCreds)));
        String t = Files.readString(tmpCreds);
        assertTrue(t.contains("arflex.console.username=integrator") && holdsPbkdf2Of(t, "s3cret-Pass"), t);
        assertFalse(t.contains("s3cret-Pass"), t);
        assertEquals(stored, Files.readString(creds));

        // A user name that would write another property into the file is refused, and named.
        Run bad = login(home, Map.of("ARFLEX_CONSOLE_USER", "x\nfelix.webconsole.password=", "ARFLEX_CONSOLE_PASSWORD", "p"));
        assertEquals(2, bad.exit(), bad.text());
        assertTrue(bad.text().contains("ARFLEX_CONSOLE_USER"), bad.text());

        // The same password stored twice gets two salts.
        Run again = login(home, Map.of("ARFLEX_CONSOLE_PASSWORD", "s3cret-Pass"));
        String t2 = Files.readString(Path.of(again.lines().get(again.lines().size() - 1)));
        assertTrue(holdsPbkdf2Of(t2, "s3cret-Pass"), t2);
        assertNotEquals(t.substring(t.indexOf('$')), t2.substring(t2.indexOf('$')), "no salt");

        // A file of an earlier version (unsalted SHA-256) is refused, saying what to do, and kept.
        String old = "felix.webconsole.username=arflex\nfelix.webconsole.password={sha-256}jGl25bVBBBW96Qi9Te4V37Fnqchz/Eu4qB9vKrRIqRg=\n";
        Files.writeString(creds, old);
        Run refused = login(home, Map.of());
        assertEquals(2, refused.exit(), refused.text());
        assertTrue(refused.text().contains(creds.toString()) && refused.text().contains("unsalted")
                && refused.text().contains("Remove that file") && refused.text().contains("ARFLEX_CONSOLE_PASSWORD"),
                refused.text());
        assertEquals(old, Files.readString(creds));
    }

    static int status(URI uri, String basicAuth) {
        try {
            HttpURLConnection c = (HttpURLConnection) uri.toURL().openConnection();
            c.setConnectTimeout(2000);
            c.setReadTimeout(5000);
            c.setInstanceFollowRedirects(false);
            if (basicAuth != null) {
                c.setRequestProperty("Authorization",
                        "Basic " + Base64.getEncoder().encodeToString(basicAuth.getBytes(StandardCharsets.UTF_8)));
            }
            int s = c.getResponseCode();
            c.disconnect();
            return s;
        } catch (IOException e) {
            lastError = e.toString();
            return -1;
        }
    }

    /** The last I/O error of {@link #status}, for failure messages. */
    static volatile String lastError = "";

    static void await(String what, long timeoutMs, BooleanSupplier cond, List<String> output) {
        long deadline = System.nanoTime() + timeoutMs * 1_000_000L;
        while (!cond.getAsBoolean()) {
            if (System.nanoTime() - deadline > 0) {
                List<String> tail = output.subList(Math.max(0, output.size() - 60), output.size());
                fail("timed out after " + timeoutMs + " ms waiting for " + what + "; last output:\n" + String.join("\n", tail));
            }
            java.util.concurrent.locks.LockSupport.parkNanos(100_000_000L);
        }
    }

    @Test
    void theHeadlessMainJobRunsTheCellBehindTheLoginOnLoopbackOnlyAndStopsCleanly(@TempDir Path tmp) throws Exception {
        HeadlessRun run = HeadlessRun.copy("mainjob-assembly");
        Path copy = run.assembly();
        int port = run.port();
        int seconds = 40;
        ProcessBuilder pb = run.command(seconds, tmp.resolve("home"));
        List<String> out = new CopyOnWriteArrayList<>();
        Process p = pb.start();
        Thread reader = new Thread(() -> {
            try (BufferedReader r = new BufferedReader(new InputStreamReader(p.getInputStream(), StandardCharsets.UTF_8))) {
                for (String l; (l = r.readLine()) != null; ) {
                    out.add(l);
                }
            } catch (IOException ignored) {
                // the pipe closes when the job ends
            }
        }, "mainjob-output");
        reader.start();
        String rid = null;
        try {
            await("the generated login", 60_000, () -> out.stream().anyMatch(l -> PASSWORD.matcher(l).find()), out);
            Matcher m = PASSWORD.matcher(out.stream().filter(l -> PASSWORD.matcher(l).find()).findFirst().orElseThrow());
            assertTrue(m.find());
            String login = m.group(1) + ":" + m.group(2);
            Pattern ridP = Pattern.compile("DRCR started, runtime id ([a-z0-9-]+)");
            await("the DRCR", T, () -> out.stream().anyMatch(l -> ridP.matcher(l).find()), out);
            Matcher rm = ridP.matcher(out.stream().filter(l -> ridP.matcher(l).find()).findFirst().orElseThrow());
            assertTrue(rm.find());
            rid = rm.group(1);

            URI cell = URI.create("http://127.0.0.1:" + port + "/system/console/arflex-cell");
            int[] last = {0};
            try {
                await("the console's cell page with the generated login", T, () -> (last[0] = status(cell, login)) == 200, out);
            } catch (AssertionError e) {
                Path dump = Path.of(System.getProperty("arflex.it.work")).resolve("mainjob-output.txt");
                Files.write(dump, out);
                throw new AssertionError("last status " + last[0] + " (" + lastError + "), whole output in " + dump + "; "
                        + e.getMessage(), e);
            }
            assertEquals(401, status(cell, null), "without credentials");
            assertEquals(401, status(cell, "admin:admin"), "the Web Console's default login");
            assertEquals(401, status(cell, m.group(1) + ":" + m.group(2) + "x"), "a wrong password");
            // Loopback only: every other address of this machine refuses the connection.
            List<InetAddress> others = new ArrayList<>();
            for (NetworkInterface ni : java.util.Collections.list(NetworkInterface.getNetworkInterfaces())) {
                if (ni.isUp() && !ni.isLoopback()) {
                    for (InetAddress a : java.util.Collections.list(ni.getInetAddresses())) {
                        if (a instanceof Inet4Address) {
                            others.add(a);
                        }
                    }
                }
            }
            for (InetAddress a : others) {
                try (Socket s = new Socket()) {
                    s.connect(new InetSocketAddress(a, port), 2000);
                    fail("the console answers on " + a.getHostAddress() + ":" + port + ", not only on the loopback");
                } catch (ConnectException expected) {
                    // refused: nothing listens there
                }
            }
            System.out.println("MainJobIT: console on 127.0.0.1:" + port + " only (refused on " + others + ")");

            await("a cell summary with the true TCP error", T,
                    () -> out.stream().anyMatch(l -> l.contains("arflex cell: ") && l.contains("TRUE TCP error")), out);
            assertTrue(p.waitFor(seconds + 120, TimeUnit.SECONDS), "the headless job did not stop after " + seconds + " s");
            reader.join(10_000);
            assertEquals(0, p.exitValue(), "exit status; last output:\n" + String.join("\n",
                    out.subList(Math.max(0, out.size() - 40), out.size())));
            // The last arflex:list shows the whole cell ACTIVE.
            int header = -1;
            for (int i = 0; i < out.size(); i++) {
                if (out.get(i).matches(".*\\bNAME\\s+STATE\\s+PID.*")) {
                    header = i;
                }
            }
            assertTrue(header >= 0, "no arflex:list output");
            List<String> table = out.subList(header, out.size());
            // what the runtime and the halves said about stalls, safe modes and lost inputs
            // (the cause of a component that is not ACTIVE, when it happened early)
            String why = out.stream().filter(l -> l.contains("safe mode") || l.contains("silent for")
                    || l.contains("answered after") || l.contains("hung") || l.contains("lost")
                    || l.contains("overran") || l.contains("reset")).limit(60)
                    .collect(java.util.stream.Collectors.joining("\n"));
            for (String name : CellE2EIT.CELL) {
                assertTrue(table.stream().anyMatch(l -> l.matches(".*\\b" + Pattern.quote(name) + "\\s+ACTIVE\\b.*")),
                        name + " not ACTIVE in the last arflex:list:\n" + String.join("\n", table) + "\n--- from its output:\n"
                                + why);
            }
            // Readiness from the DRCR, not from the log: the console's arflex:await answered for
            // vision (before its settings) and for the whole cell (before the first arflex:list).
            assertTrue(out.stream().anyMatch(l -> l.matches("(g! )*vision ACTIVE \\(after \\d+\\.\\d s\\)")),
                    "no arflex:await answer for vision");
            assertTrue(out.stream().anyMatch(l -> l.matches("(g! )*cell ACTIVE: " + CellE2EIT.CELL.size()
                    + " components \\(after \\d+\\.\\d s\\)")), "no arflex:await --cell answer");
            assertTrue(out.stream().noneMatch(l -> l.matches("(g! )*error: .*")), "a command failed:\n" + String.join("\n", out));
            // The summary is arflex:summary's answer in the console (a line may begin with its
            // prompt): every component's RT half, the robot's cycles, the TRUE TCP error.
            Pattern summaryP = Pattern.compile("^(?:g! )*arflex cell: (\\d+) RT halves running; .*robot seq \\d+;.*"
                    + "TRUE TCP error \\d+\\.\\d{4} mm \\((?:at rest|moving)\\)$");
            List<String> summaries = out.stream().filter(l -> l.contains("arflex cell: ")).toList();
            assertTrue(summaries.size() >= 3, "fewer than 3 summaries in a " + seconds + " s run: " + summaries);
            String summary = summaries.get(summaries.size() - 1);
            Matcher sm = summaryP.matcher(summary);
            assertTrue(sm.find(), "not arflex:summary's line: " + summary);
            assertEquals(CellE2EIT.CELL.size(), Integer.parseInt(sm.group(1)), summary);
            System.out.println("MainJobIT: " + summary);
        } finally {
            if (p.isAlive()) {
                p.descendants().forEach(ProcessHandle::destroyForcibly);
                p.destroyForcibly();
                p.waitFor(30, TimeUnit.SECONDS);
            }
        }
        // Nothing of the job is left: no shared memory, no queue, no log or temporary login.
        String prefix = "arflex." + rid + ".";
        for (String dir : new String[] {"/dev/shm", "/dev/mqueue"}) {
            Path d = Path.of(dir);
            if (Files.isDirectory(d)) {
                try (var l = Files.list(d)) {
                    List<String> left = l.map(x -> x.getFileName().toString()).filter(n -> n.startsWith(prefix)).toList();
                    assertEquals(List.of(), left, "left in " + dir);
                }
            }
        }
        // The home keeps the login and the console's audit of the logins tried above (D81), private.
        try (var l = Files.list(tmp.resolve("home"))) {
            assertEquals(List.of("console-audit.log", "console-security.log", "console.properties"),
                    l.map(x -> x.getFileName().toString()).sorted().toList());
        }
        Path security = tmp.resolve("home/console-security.log");
        assertEquals("rw-------", PosixFilePermissions.toString(Files.getPosixFilePermissions(security)));
        String history = Files.readString(security);
        assertTrue(history.contains("\"method\":\"LOGIN\"") && history.contains("\"status\":401"), history);
        Runtime.deleteTree(copy);
    }
}
