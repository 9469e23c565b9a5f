package org.arflex.webconsole.impl;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import jakarta.servlet.FilterChain;
import jakarta.servlet.http.HttpServletRequest;
import jakarta.servlet.http.HttpServletResponse;
import java.lang.reflect.Proxy;
import java.nio.charset.StandardCharsets;
import java.nio.file.Path;
import java.time.Clock;
import java.time.Instant;
import java.time.ZoneOffset;
import java.util.Base64;
import java.util.HashMap;
import java.util.List;
import java.util.Map;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;

/** What the audit filter records of a request, refusals by the cross-site guard included. */
class AuditFilterTest {
    private static final String SELF = "http://127.0.0.1:8480";

    @TempDir
    Path tmp;

    private AuditLog log() {
        return new AuditLog(tmp.resolve("console-audit.log"), 1 << 16, 2,
                Clock.fixed(Instant.parse("2026-11-25T10:00:00Z"), ZoneOffset.UTC));
    }

    private static HttpServletRequest request(String method, String uri, String query, String user,
            Map<String, String> headers, Map<String, String> form) {
        Map<String, Object> attrs = new HashMap<>();
        return (HttpServletRequest) Proxy.newProxyInstance(AuditFilterTest.class.getClassLoader(),
                new Class<?>[] {HttpServletRequest.class}, (p, m, a) -> switch (m.getName()) {
                    case "getMethod" -> method;
                    case "getRequestURI" -> uri;
                    case "getQueryString" -> query;
                    case "getContextPath" -> "";
                    case "getHeader" -> headers.get((String) a[0]);
                    case "getContentType" -> form == null ? null : "application/x-www-form-urlencoded";
                    case "getParameter" -> form == null ? null : form.get((String) a[0]);
                    case "getRemoteUser" -> user;
                    case "getRemoteAddr" -> "127.0.0.1";
                    case "getScheme" -> "http";
                    case "getLocalPort" -> 8480;
                    case "getLocalAddr" -> "127.0.0.1";
                    case "getLocalName" -> "localhost";
                    case "setAttribute" -> attrs.put((String) a[0], a[1]);
                    case "getAttribute" -> attrs.get((String) a[0]);
                    case "hashCode" -> System.identityHashCode(p);
                    case "equals" -> p == a[0];
                    default -> null;
                });
    }

    private static HttpServletResponse response() {
        int[] status = {200};
        return (HttpServletResponse) Proxy.newProxyInstance(AuditFilterTest.class.getClassLoader(),
                new Class<?>[] {HttpServletResponse.class}, (p, m, a) -> switch (m.getName()) {
                    case "sendError", "setStatus" -> {
                        status[0] = (Integer) a[0];
                        yield null;
                    }
                    case "getStatus" -> status[0];
                    case "isCommitted" -> false;
                    default -> null;
                });
    }

    private static final FilterChain OK = (rq, rs) -> { };

    @Test
    void readsAreNotRecorded() throws Exception {
        AuditLog log = log();
        new AuditFilter(log).doFilter(request("GET", "/system/console/bundles", null, "arflex", Map.of(), null), response(), OK);
        new AuditFilter(log).doFilter(request("HEAD", "/system/console/bundles", null, "arflex", Map.of(), null), response(), OK);
        assertEquals(List.of(), log.recent(10));
    }

    @Test
    void aConsoleChangeIsRecordedWithWhoWhatAndTheStatus() throws Exception {
        AuditLog log = log();
        new AuditFilter(log).doFilter(request("POST", "/system/console/bundles/42", null, "arflex",
                Map.of("Origin", SELF, "Host", "127.0.0.1:8480"), Map.of("action", "uninstall", "other", "x")), response(), OK);
        AuditLog.Entry e = log.recent(10).get(0);
        assertEquals("arflex", e.user());
        assertEquals("127.0.0.1", e.remote());
        assertEquals("POST", e.method());
        assertEquals("/system/console/bundles/42", e.path());
        assertEquals(Map.of("action", "uninstall"), e.params(), "only the parameters that say what was asked");
        assertEquals(200, e.status());
        assertEquals("2026-11-25T10:00:00Z", e.time());
    }

    @Test
    void ourApiParametersComeFromTheQueryString() throws Exception {
        AuditLog log = log();
        new AuditFilter(log).doFilter(request("POST", "/system/console/arflex-component/api/param",
                "name=sample-scaler&param=gain&value=4.25&junk=1", "arflex", Map.of(), null), response(), OK);
        assertEquals(Map.of("name", "sample-scaler", "param", "gain", "value", "4.25"), log.recent(1).get(0).params());
    }

    @Test
    void aCrossSiteRefusalThroughAnEncodedPathIsRecordedWithTheReason() throws Exception {
        AuditLog log = log();
        FilterChain guarded = (rq, rs) -> new CrossSiteFilter().doFilter(rq, rs, (a, b) -> {
            throw new AssertionError("must not reach the console");
        });
        HttpServletResponse resp = response();
        new AuditFilter(log).doFilter(request("POST", "/%73ystem/console/bundles/42", null, "arflex",
                Map.of("Origin", "http://127.0.0.1:9999", "Host", "127.0.0.1:8480", "Sec-Fetch-Site", "same-site"),
                Map.of("action", "uninstall")), resp, guarded);
        AuditLog.Entry e = log.recent(1).get(0);
        assertEquals(403, e.status());
        assertEquals("/system/console/bundles/42", e.path(), "the path as the guard reads it");
        assertEquals(Map.of("action", "uninstall", "origin", "http://127.0.0.1:9999"), e.params());
        assertTrue(e.reason().contains("cross-site"), e.reason());
    }

    @Test
    void aFailureIsRecordedAs500AndStillThrown() throws Exception {
        AuditLog log = log();
        FilterChain broken = (rq, rs) -> {
            throw new IllegalStateException("boom");
        };
        assertThrows(IllegalStateException.class, () -> new AuditFilter(log).doFilter(
                request("POST", "/system/console/configMgr/x", null, "arflex", Map.of(), null), response(), broken));
        AuditLog.Entry e = log.recent(1).get(0);
        assertEquals(500, e.status());
        assertEquals("IllegalStateException: boom", e.reason());
    }

    @Test
    void theUserComesFromTheBasicLoginWhenTheContainerDoesNotSay() throws Exception {
        AuditLog log = log();
        String basic = "Basic " + Base64.getEncoder().encodeToString("ops:secret".getBytes(StandardCharsets.UTF_8));
        new AuditFilter(log).doFilter(request("DELETE", "/system/console/configMgr/x", null, null,
                Map.of("Authorization", basic), null), response(), OK);
        AuditLog.Entry e = log.recent(1).get(0);
        assertEquals("ops", e.user());
        assertEquals("DELETE", e.method());
    }

    @Test
    void outsideTheConsoleNothingIsRecorded() throws Exception {
        AuditLog log = log();
        new AuditFilter(log).doFilter(request("POST", "/other/thing", null, "arflex", Map.of(), null), response(), OK);
        assertEquals(List.of(), log.recent(10));
    }

    private static FilterChain guarded() {
        return (rq, rs) -> new CrossSiteFilter().doFilter(rq, rs, (a, b) -> {
            throw new AssertionError("must not reach the console");
        });
    }

    /** Issue 30's flood: every recorded parameter 250 characters long. */
    private static Map<String, String> floodForm() {
        Map<String, String> form = new HashMap<>();
        for (String k : AuditFilter.PARAMS) {
            form.put(k, "v".repeat(250));
        }
        return form;
    }

    private static final Map<String, String> CROSS_SITE = Map.of("Origin", "http://evil.example", "Host", "127.0.0.1:8480",
            "Sec-Fetch-Site", "cross-site");

    @Test
    void aCrossSiteFloodDoesNotPushEarlierEntriesOutOfTheLog() throws Exception {
        // The console's rotation (files kept beside the current one) on smaller files.
        AuditLog log = new AuditLog(tmp.resolve("console-audit.log"), 1 << 16, 3,
                Clock.fixed(Instant.parse("2026-11-25T10:00:00Z"), ZoneOffset.UTC));
        AuditFilter filter = new AuditFilter(log);
        filter.doFilter(request("POST", "/system/console/bundles/42", null, "arflex",
                Map.of("Origin", SELF, "Host", "127.0.0.1:8480"), Map.of("action", "uninstall")), response(), OK);
        for (int i = 0; i < 1400; i++) {
            filter.doFilter(request("POST", "/system/console/bundles/0", null, "arflex", CROSS_SITE, floodForm()), response(),
                    guarded());
        }
        List<AuditLog.Entry> all = log.recent(100_000);
        assertTrue(all.stream().anyMatch(e -> "/system/console/bundles/42".equals(e.path()) && e.status() == 200),
                "the earlier entry was pushed out by the flood (" + all.size() + " entries left)");
        List<AuditLog.Entry> flood = all.stream().filter(e -> e.status() == 403).toList();
        assertTrue(flood.size() <= 10, flood.size() + " refusals written one by one");
        assertTrue(flood.stream().allMatch(e -> e.params().values().stream().noneMatch(v -> v.contains("v".repeat(33)))),
                "a refused request's parameters written in full");
    }

    @Test
    void theRefusalsNotWrittenAreCountedPerOriginAndSummedUpOnceTheMinuteIsOver() throws Exception {
        LoginLimiterTest.TestClock clock = new LoginLimiterTest.TestClock();
        AuditLog main = new AuditLog(tmp.resolve("console-audit.log"), 1 << 16, 3, clock);
        AuditLog security = new AuditLog(tmp.resolve("console-security.log"), 1 << 16, 3, clock);
        AuditTrail trail = new AuditTrail(main, security, clock);
        AuditFilter filter = new AuditFilter(trail);
        filter.doFilter(request("POST", "/system/console/bundles/42", null, "arflex",
                Map.of("Origin", SELF, "Host", "127.0.0.1:8480"), Map.of("action", "uninstall")), response(), OK);
        for (int i = 0; i < 1400; i++) {
            filter.doFilter(request("POST", "/system/console/bundles/0", null, "arflex", CROSS_SITE, floodForm()), response(),
                    guarded());
        }
        assertEquals(Map.of("http://evil.example", 1395L), trail.refusalsNotWritten());
        clock.advance(java.time.Duration.ofSeconds(61));
        // the next entry brings the summary of the minute that is over first
        filter.doFilter(request("POST", "/system/console/bundles/43", null, "arflex",
                Map.of("Origin", SELF, "Host", "127.0.0.1:8480"), Map.of("action", "stop")), response(), OK);
        for (AuditLog log : List.of(main, security)) {
            List<AuditLog.Entry> all = log.recent(1000);
            AuditLog.Entry summary = all.stream().filter(e -> "REFUSED".equals(e.method())).findFirst().orElseThrow();
            assertEquals("1395", summary.params().get("count"), summary.toString());
            assertEquals("1395", summary.params().get("http://evil.example"));
            assertTrue(summary.reason().startsWith("1395 more refused requests between ")
                    && summary.reason().endsWith("not written one by one: http://evil.example 1395"), summary.reason());
            assertEquals(5, all.stream().filter(e -> "POST".equals(e.method()) && e.status() == 403).count());
        }
        // the security history holds the changes, not the ordinary traffic
        assertTrue(security.recent(100).stream().anyMatch(e -> "/system/console/bundles/42".equals(e.path())));
        assertTrue(security.recent(100).stream().anyMatch(e -> "/system/console/bundles/43".equals(e.path())));
    }

    @Test
    void aFailedRequestIsInTheLogButNotTheSecurityHistory() throws Exception {
        LoginLimiterTest.TestClock clock = new LoginLimiterTest.TestClock();
        AuditLog main = new AuditLog(tmp.resolve("console-audit.log"), 1 << 16, 3, clock);
        AuditLog security = new AuditLog(tmp.resolve("console-security.log"), 1 << 16, 3, clock);
        FilterChain notFound = (rq, rs) -> ((HttpServletResponse) rs).sendError(404);
        new AuditFilter(new AuditTrail(main, security, clock)).doFilter(request("POST", "/system/console/arflex-cell/api/command",
                "name=nope&cmd=stop", "arflex", Map.of(), null), response(), notFound);
        assertEquals(404, main.recent(1).get(0).status());
        assertEquals(List.of(), security.recent(10));
    }
}
