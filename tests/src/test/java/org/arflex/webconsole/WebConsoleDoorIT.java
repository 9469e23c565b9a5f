package org.arflex.webconsole;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertTrue;

import com.sun.net.httpserver.HttpServer;
import java.io.IOException;
import java.net.InetSocketAddress;
import java.net.URI;
import java.net.http.HttpRequest;
import java.net.http.HttpResponse;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.time.Duration;
import java.util.List;
import java.util.Map;
import java.util.TreeMap;
import java.util.stream.Stream;
import org.junit.jupiter.api.MethodOrderer;
import org.junit.jupiter.api.Order;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.TestMethodOrder;
import org.junit.jupiter.api.extension.RegisterExtension;
import org.openqa.selenium.By;

/**
 * The console's door in Debian's headless Chromium against the real runtime (child process):
 * no page without the console's login (none, a wrong one, the Web Console's default), the
 * login opens the cell, and forged posts (no or a wrong CSRF token; forms on another origin
 * submitted while the browser holds the login) are refused. Screenshots to target/screenshots/.
 * Issue 30: a cross-site flood does not push earlier entries out of the audit log (finding 6),
 * and password guessing is slowed, refused with 429 and audited (finding 7); last, because the
 * guessing puts this client address into back-off.
 */
@TestMethodOrder(MethodOrderer.OrderAnnotation.class)
class WebConsoleDoorIT {
    @RegisterExtension
    static final ConsoleFixture FX = ConsoleFixture.withBrowser("webconsole-door");
    private static final ConsolePages PAGES = FX.pages();

    @Test
    @Order(1)
    void refusedWithoutOrWithWrongCredentials() throws IOException {
        HttpResponse<String> none = FX.rt().get("/system/console/arflex-cell", false);
        assertEquals(401, none.statusCode());
        assertTrue(none.headers().firstValue("WWW-Authenticate").orElse("").startsWith("Basic"));
        HttpResponse<String> wrong = FX.rt().send(HttpRequest.newBuilder(URI.create(FX.rt().base() + "/system/console/arflex-cell/api/cell"))
                .header("Authorization", "Basic " + java.util.Base64.getEncoder().encodeToString("arflex:admin".getBytes(StandardCharsets.UTF_8))), false);
        assertEquals(401, wrong.statusCode());
        HttpResponse<String> admin = FX.rt().send(HttpRequest.newBuilder(URI.create(FX.rt().base() + "/system/console/bundles"))
                .header("Authorization", "Basic " + java.util.Base64.getEncoder().encodeToString("admin:admin".getBytes(StandardCharsets.UTF_8))), false);
        assertEquals(401, admin.statusCode(), "the Web Console default login must not work");
        // The PAGES.driver() without credentials gets no page either.
        PAGES.open("arflex-cell");
        assertFalse(PAGES.driver().getPageSource().contains("arflex-app"));
        PAGES.shot("00-refused");
    }

    @Test
    @Order(2)
    void loginAndSeeTheCell() throws IOException {
        PAGES.login();
        PAGES.open("arflex-cell");
        PAGES.await(By.id("arflex-instances"));
        PAGES.awaitText(By.id("arflex-cell-status"), "Runtime");
        assertTrue(PAGES.driver().findElement(By.id("arflex-resources")).getText().contains("CPU"));
        PAGES.shot("01-cell-empty");
    }

    @Test
    @Order(3)
    void forgedCrossSitePostsAreRefused() throws IOException {
        // Without a token, with a wrong token: refused with 403 before anything happens.
        HttpResponse<String> noToken = FX.rt().send(HttpRequest.newBuilder(URI.create(FX.rt().base()
                + "/system/console/arflex-deploy/api/uninstall?name=sample-counter"))
                .header("Origin", FX.rt().base()).POST(HttpRequest.BodyPublishers.noBody()), true);
        assertEquals(403, noToken.statusCode());
        assertTrue(noToken.body().contains("CSRF"), noToken.body());
        HttpResponse<String> wrongToken = FX.rt().send(HttpRequest.newBuilder(URI.create(FX.rt().base()
                + "/system/console/arflex-deploy/api/uninstall?name=sample-counter"))
                .header("Origin", FX.rt().base()).header("X-Arflex-Csrf", "forged").POST(HttpRequest.BodyPublishers.noBody()), true);
        assertEquals(403, wrongToken.statusCode());

        // A page on another origin submits forms at the console while the PAGES.driver() holds the
        // credentials: ours and the Web Console's own (stop the system bundle).
        HttpServer evil = HttpServer.create(new InetSocketAddress("127.0.0.1", 0), 0);
        String target = FX.rt().base() + "/system/console";
        String page = "<html><body><form id='f1' method='POST' action='" + target
                + "/arflex-contract/api/save?name=forged'><input name='_csrf' value='guess'></form>"
                + "<form id='f2' method='POST' action='" + target + "/bundles/0'>"
                + "<input name='action' value='stop'></form>"
                + "<p id='which'></p><script>var w=location.hash.substring(1);document.getElementById(w).submit();</script></body></html>";
        evil.createContext("/evil", ex -> {
            byte[] b = page.getBytes(StandardCharsets.UTF_8);
            ex.getResponseHeaders().add("Content-Type", "text/html");
            ex.sendResponseHeaders(200, b.length);
            ex.getResponseBody().write(b);
            ex.close();
        });
        evil.start();
        try {
            String evilBase = "http://localhost:" + evil.getAddress().getPort() + "/evil";
            PAGES.driver().get(evilBase + "#f1");
            PAGES.waiting().until(d -> d.getCurrentUrl().contains("/api/save"));
            assertTrue(PAGES.driver().getPageSource().contains("cross-"), PAGES.driver().getPageSource());
            PAGES.shot("02-forged-post-refused");
            assertFalse(Files.exists(FX.rt().home.resolve("contracts/forged.xml")));
            PAGES.driver().get(evilBase + "#f2");
            PAGES.waiting().until(d -> d.getCurrentUrl().contains("/bundles/0"));
            assertTrue(PAGES.driver().getPageSource().contains("403"), PAGES.driver().getPageSource());
        } finally {
            evil.stop(0);
        }
        assertEquals(200, FX.rt().get("/system/console/arflex-cell/api/cell", true).statusCode(), "the runtime still runs");
    }

    @Test
    @Order(4)
    void aCrossSiteFloodDoesNotPushEarlierEntriesOutOfTheAuditLog() throws IOException {
        // An earlier entry: a configuration written from the console's own origin.
        String base = FX.rt().base();
        HttpResponse<String> marker = FX.rt().send(HttpRequest.newBuilder(URI.create(base
                + "/system/console/configMgr/org.arflex.door.marker")).header("Origin", base)
                .header("Content-Type", "application/x-www-form-urlencoded")
                .POST(HttpRequest.BodyPublishers.ofString("apply=true&action=ajaxConfigManager&propertylist=x&x=1")), true);
        assertTrue(marker.statusCode() < 400, "the marker write: " + marker.statusCode());
        // The flood of issue 30: 1,400 refused cross-site posts with long parameters, sent with
        // the login as the operator's browser would.
        String query = LoginAndAuditDoors.floodQuery();
        for (int i = 0; i < 1400; i++) {
            HttpResponse<String> r = FX.rt().send(HttpRequest.newBuilder(URI.create(base + "/system/console/bundles/0?" + query))
                    .header("Origin", "http://evil.example").header("Sec-Fetch-Site", "cross-site")
                    .POST(HttpRequest.BodyPublishers.noBody()), true);
            assertEquals(403, r.statusCode(), "flood post " + i);
        }
        List<String> lines = LoginAndAuditDoors.auditLines(FX.rt().home, "console-audit.log");
        assertTrue(lines.stream().anyMatch(l -> l.contains("org.arflex.door.marker")),
                "the marker entry was pushed out of the audit log by the flood (" + lines.size() + " lines left)");
        long flood = lines.stream().filter(l -> l.contains("evil.example")).count();
        assertTrue(flood <= 40, flood + " lines of the flood written one by one");
        assertTrue(lines.stream().noneMatch(l -> l.contains("v".repeat(100))), "a refused request's full parameters were written");
        // The security history (logins, changes, refusal summaries) has the change too, and the
        // Audit page counts the refusals not written one by one, per origin.
        assertTrue(LoginAndAuditDoors.auditLines(FX.rt().home, "console-security.log").stream().anyMatch(l -> l.contains("org.arflex.door.marker")),
                "the change is not in the security history");
        String audit = FX.rt().get("/system/console/arflex-audit/api/audit?max=5", true).body();
        java.util.regex.Matcher pending = java.util.regex.Pattern.compile("\"refusalsNotWritten\":\\{[^}]*\"http://evil.example\":(\\d+)")
                .matcher(audit);
        long counted = pending.find() ? Long.parseLong(pending.group(1)) : 0;
        // read again: the answer wrote the summary of a minute that ended meanwhile
        lines = LoginAndAuditDoors.auditLines(FX.rt().home, "console-audit.log");
        java.util.regex.Pattern summary = java.util.regex.Pattern.compile("\"http://evil.example\":\"(\\d+)\"");
        for (String l : lines) {
            java.util.regex.Matcher m = summary.matcher(l);
            counted += m.find() ? Long.parseLong(m.group(1)) : 0;
        }
        long samples = lines.stream().filter(l -> l.contains("evil.example") && l.contains("\"method\":\"POST\"")).count();
        assertEquals(1400, samples + counted, "every refusal written as a sample or counted (" + samples + " samples); " + audit);
    }

    @Test
    @Order(5)
    void passwordGuessingIsSlowedRefusedAndAuditedAndTheRightPasswordWorksAfter() throws IOException {
        Map<Integer, Integer> statuses = new TreeMap<>();
        String retryAfter = null;
        for (int i = 0; i < 300; i++) {
            HttpResponse<String> r = FX.rt().send(HttpRequest.newBuilder(URI.create(FX.rt().base() + "/system/console/arflex-cell/api/cell"))
                    .header("Authorization", "Basic " + java.util.Base64.getEncoder().encodeToString(
                            ("arflex:guess-" + i).getBytes(StandardCharsets.UTF_8))), false);
            statuses.merge(r.statusCode(), 1, Integer::sum);
            if (r.statusCode() == 429) {
                retryAfter = r.headers().firstValue("Retry-After").orElse(null);
            }
        }
        assertTrue(statuses.getOrDefault(429, 0) >= 250, "guesses answered " + statuses);
        assertTrue(statuses.getOrDefault(401, 0) <= 15, "guesses checked " + statuses);
        assertTrue(retryAfter != null && retryAfter.matches("\\d+"), "Retry-After " + retryAfter);
        List<String> security = LoginAndAuditDoors.auditLines(FX.rt().home, "console-security.log");
        long failed = security.stream().filter(l -> l.contains("\"method\":\"LOGIN\"") && l.contains("\"status\":401")).count();
        assertTrue(failed >= 1 && failed <= 15, failed + " failed logins in the security history");
        assertTrue(security.stream().anyMatch(l -> l.contains("\"method\":\"LOGIN\"") && l.contains("\"status\":429")),
                "no back-off in the security history");
        // The stored login is a salted slow hash.
        try (Stream<Path> s = Files.list(FX.rt().home)) {
            List<Path> creds = s.filter(p -> p.getFileName().toString().matches("console\\..*properties")).toList();
            assertFalse(creds.isEmpty(), "no credentials file in " + FX.rt().home);
            for (Path c : creds) {
                String text = Files.readString(c);
                assertTrue(text.contains("{pbkdf2-sha256}") && !text.contains("{sha-256}"), c + ": " + text);
            }
        }
        // After the back-off the right password works (a client without a session of its own).
        RuntimeUnderTest.awaitCondition("the right password after the back-off", Duration.ofSeconds(90),
                () -> {
                    HttpResponse<String> r = FX.rt().get("/system/console/arflex-cell/api/cell", true);
                    return r != null && r.statusCode() == 200;
                });
    }
}
