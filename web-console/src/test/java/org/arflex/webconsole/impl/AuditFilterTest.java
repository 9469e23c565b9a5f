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
        assertEquals(Map.of("action", "uninstall"), e.params());
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
}
