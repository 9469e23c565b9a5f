package org.arflex.webconsole;

import java.io.IOException;
import java.net.URI;
import java.net.http.HttpClient;
import java.net.http.HttpRequest;
import java.net.http.HttpResponse;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.time.Duration;
import java.util.ArrayList;
import java.util.Base64;
import java.util.List;
import java.util.Map;
import java.util.TreeMap;

/**
 * Issue 30's doors of the console's attack bench ({@link ConsoleAttackBench}): a cross-site flood
 * that would push earlier entries out of the audit log (finding 6), and a burst of password
 * guesses (finding 7). Run last: the guessing puts the bench's address into back-off, and the
 * control at the end waits (on the answer, with a deadline) until the right password works again.
 */
final class LoginAndAuditDoors {
    /** Where a door's attempts go: the bench's one line per door. */
    interface Recorder {
        void record(String door, int tries, int succeeded, String detail);
    }

    /** Wrong guesses checked (answered 401) within a burst that the back-off may allow. */
    static final int CHECKED_BUDGET = 20;

    private final RuntimeUnderTest rt;
    private final Recorder out;
    private final HttpClient http = HttpClient.newBuilder().connectTimeout(Duration.ofSeconds(5)).build();

    LoginAndAuditDoors(RuntimeUnderTest rt, Recorder out) {
        this.rt = rt;
        this.out = out;
    }

    /** Both doors, the flood first (the guessing leaves this address in back-off for a while). */
    void run() throws IOException {
        crossSiteFlood();
        guessingBurst();
    }

    /** The parameters the audit log records of a request (AuditFilter.PARAMS), each 250 characters. */
    static String floodQuery() {
        StringBuilder q = new StringBuilder();
        for (String k : List.of("action", "name", "param", "value", "cmd", "id", "file", "url", "sha256", "targets",
                "apply", "delete", "propertylist", "factoryPid", "shutdown_type")) {
            q.append(q.length() == 0 ? "" : "&").append(k).append('=').append("v".repeat(250));
        }
        return q.toString();
    }

    /** Every line of an audit file of the home and its rotated files, oldest file first. */
    static List<String> auditLines(Path home, String file) throws IOException {
        List<String> lines = new ArrayList<>();
        for (int i = 9; i >= 0; i--) {
            Path p = home.resolve(i == 0 ? file : file + "." + i);
            if (Files.isRegularFile(p)) {
                lines.addAll(Files.readAllLines(p, StandardCharsets.UTF_8));
            }
        }
        return lines;
    }

    /**
     * A change from the console's own origin, then 1,400 cross-site posts with every recorded
     * parameter 250 characters long, sent with the login as the operator's browser would. One
     * attempt per post written in full to the audit log, one if the change is gone from it.
     */
    private void crossSiteFlood() throws IOException {
        String base = rt.base();
        String marker = "org.arflex.attack.marker" + System.nanoTime();
        HttpResponse<String> change = send(HttpRequest.newBuilder(URI.create(base + "/system/console/configMgr/" + marker))
                .header("Authorization", rt.basicAuth()).header("Origin", base)
                .header("Content-Type", "application/x-www-form-urlencoded")
                .POST(HttpRequest.BodyPublishers.ofString("apply=true&action=ajaxConfigManager&propertylist=x&x=1")));
        if (change == null || change.statusCode() >= 400) {
            throw new AssertionError("control failed: a configuration write from the console's origin answered "
                    + (change == null ? "nothing" : change.statusCode()));
        }
        String query = floodQuery();
        Map<Integer, Integer> statuses = new TreeMap<>();
        for (int i = 0; i < 1400; i++) {
            HttpResponse<String> r = send(HttpRequest.newBuilder(URI.create(base + "/system/console/bundles/0?" + query))
                    .header("Authorization", rt.basicAuth()).header("Origin", "http://evil.example")
                    .header("Sec-Fetch-Site", "cross-site").POST(HttpRequest.BodyPublishers.noBody()));
            statuses.merge(r == null ? -1 : r.statusCode(), 1, Integer::sum);
        }
        List<String> lines = auditLines(rt.home, "console-audit.log");
        int full = (int) lines.stream().filter(l -> l.contains("v".repeat(250))).count();
        int accepted = statuses.entrySet().stream().filter(e -> e.getKey() >= 200 && e.getKey() < 400)
                .mapToInt(Map.Entry::getValue).sum();
        out.record("cross-site flood: refused posts written in full", 1400, Math.min(1400, full + accepted),
                "answered (status=count) " + statuses + ", " + full + " written in full, " + lines.size() + " lines in the log");
        boolean gone = lines.stream().noneMatch(l -> l.contains(marker));
        boolean kept = auditLines(rt.home, "console-security.log").stream().anyMatch(l -> l.contains(marker));
        out.record("cross-site flood: an earlier change pushed out of the log", 2, (gone ? 1 : 0) + (kept ? 0 : 1),
                (gone ? "GONE from console-audit.log" : "kept in console-audit.log") + ", "
                        + (kept ? "kept in" : "MISSING from") + " console-security.log");
    }

    /**
     * 2,000 wrong Basic logins as fast as the console answers: a guess the console checked past
     * {@value #CHECKED_BUDGET} is an attempt that succeeded (guessing not limited), and so is a
     * burst that left no failed login in the security history. Control: the right password works
     * again once the back-off is over.
     */
    private void guessingBurst() throws IOException {
        Map<Integer, Integer> statuses = new TreeMap<>();
        long t0 = System.nanoTime();
        for (int i = 0; i < 2000; i++) {
            String guess = "Basic " + Base64.getEncoder().encodeToString(("arflex:guess-" + i).getBytes(StandardCharsets.UTF_8));
            HttpResponse<String> r = send(HttpRequest.newBuilder(URI.create(rt.base() + "/system/console/arflex-cell/api/cell"))
                    .header("Authorization", guess).GET());
            statuses.merge(r == null ? -1 : r.statusCode(), 1, Integer::sum);
        }
        double seconds = (System.nanoTime() - t0) / 1e9;
        int checked = statuses.getOrDefault(401, 0);
        int accepted = statuses.getOrDefault(200, 0);
        out.record("password guessing: 2,000 wrong logins in a burst", 2000,
                Math.max(0, checked - CHECKED_BUDGET) + accepted, String.format(java.util.Locale.ROOT,
                        "answered (status=count) %s in %.1f s; checked %d (budget %d)", statuses, seconds, checked, CHECKED_BUDGET));
        long audited = auditLines(rt.home, "console-security.log").stream()
                .filter(l -> l.contains("\"method\":\"LOGIN\"") && l.contains("\"status\":401")).count();
        out.record("password guessing: failed logins not audited", 1, audited == 0 ? 1 : 0,
                audited + " failed logins written one by one to console-security.log");
        RuntimeUnderTest.awaitCondition("the right password after the back-off", Duration.ofSeconds(120), () -> {
            HttpResponse<String> r = rt.get("/system/console/arflex-cell/api/cell", true);
            return r != null && r.statusCode() == 200;
        });
        System.out.println("attack: control: the right password works after the back-off");
    }

    private HttpResponse<String> send(HttpRequest.Builder b) {
        try {
            return http.send(b.timeout(Duration.ofSeconds(10)).build(), HttpResponse.BodyHandlers.ofString());
        } catch (IOException e) {
            return null;
        } catch (InterruptedException e) {
            Thread.currentThread().interrupt();
            throw new IllegalStateException(e);
        }
    }
}
