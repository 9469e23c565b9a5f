package org.arflex.webconsole.impl;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertNotNull;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import jakarta.servlet.FilterChain;
import jakarta.servlet.http.HttpServletRequest;
import jakarta.servlet.http.HttpServletResponse;
import java.lang.reflect.Proxy;
import java.util.HashMap;
import java.util.Map;
import org.junit.jupiter.params.ParameterizedTest;
import org.junit.jupiter.params.provider.ValueSource;
import org.junit.jupiter.api.Test;

/**
 * The cross-site guard in front of every servlet under the console root, Felix's own pages
 * included (issue 16): it must decide on the path the container routes, not on the raw
 * request URI, so that an encoded, dotted or parameterised spelling of the console root cannot
 * skip it. Requests are built by hand, as in {@link CsrfTest}.
 */
class CrossSiteFilterTest {
    private static final String SELF = "http://127.0.0.1:8480";

    /** What the filter did with one request. */
    private static final class Outcome {
        boolean passed;
        Integer status;
        String reason;
    }

    /**
     * A request as a container without a whiteboard context would show it: the raw URI only
     * (context path empty, servlet path and path info unknown), so that only the filter's own
     * normalisation can find the console.
     */
    private static HttpServletRequest raw(String method, String uri, Map<String, String> headers) {
        return request(method, uri, "", null, null, headers);
    }

    private static HttpServletRequest request(String method, String uri, String contextPath, String servletPath,
            String pathInfo, Map<String, String> headers) {
        return (HttpServletRequest) Proxy.newProxyInstance(CrossSiteFilterTest.class.getClassLoader(),
                new Class<?>[] {HttpServletRequest.class}, (p, m, a) -> switch (m.getName()) {
                    case "getMethod" -> method;
                    case "getRequestURI" -> uri;
                    case "getContextPath" -> contextPath;
                    case "getServletPath" -> servletPath;
                    case "getPathInfo" -> pathInfo;
                    case "getHeader" -> headers.get((String) a[0]);
                    case "getScheme" -> "http";
                    case "getLocalPort" -> 8480;
                    case "getLocalAddr" -> "127.0.0.1";
                    case "getLocalName" -> "localhost";
                    case "hashCode" -> System.identityHashCode(p);
                    case "equals" -> p == a[0];
                    default -> null;
                });
    }

    private static Outcome run(HttpServletRequest req) throws Exception {
        Outcome o = new Outcome();
        HttpServletResponse resp = (HttpServletResponse) Proxy.newProxyInstance(
                CrossSiteFilterTest.class.getClassLoader(), new Class<?>[] {HttpServletResponse.class},
                (p, m, a) -> {
                    if (m.getName().equals("sendError")) {
                        o.status = (Integer) a[0];
                        o.reason = a.length > 1 ? (String) a[1] : null;
                    }
                    return m.getName().equals("isCommitted") ? Boolean.FALSE : null;
                });
        FilterChain chain = (rq, rs) -> o.passed = true;
        new CrossSiteFilter().doFilter(req, resp, chain);
        return o;
    }

    private static Map<String, String> h(String... kv) {
        Map<String, String> m = new HashMap<>();
        for (int i = 0; i < kv.length; i += 2) {
            m.put(kv[i], kv[i + 1]);
        }
        return m;
    }

    private static Map<String, String> foreign() {
        return h("Host", "127.0.0.1:8480", "Origin", "http://evil.example");
    }

    private static Map<String, String> sameOrigin() {
        return h("Host", "127.0.0.1:8480", "Origin", SELF, "Sec-Fetch-Site", "same-origin", Csrf.HEADER, "t0ken");
    }

    private static void assertRefused(Outcome o, String what) {
        assertEquals(Integer.valueOf(403), o.status, what + " was not refused");
        assertTrue(!o.passed, what + " reached the console");
        assertNotNull(o.reason, what + ": 403 without a reason");
    }

    /** Spellings of the console's bundle page that Jetty routes to the console. */
    @ParameterizedTest(name = "{0}")
    @ValueSource(strings = {
        "/system/console/bundles/12",
        "/%73ystem/console/bundles/12",
        "/%53ystem/console/bundles/12",
        "/system/%63onsole/bundles/12",
        "/%73%79%73%74%65%6d/%63%6f%6e%73%6f%6c%65/bundles/12",
        "/%2573ystem/console/bundles/12",
        "/%25%37%33ystem/console/bundles/12",
        "/%252573ystem/console/bundles/12",
        "%2Fsystem/console/bundles/12",
        "/%2Fsystem%2Fconsole%2Fbundles/12",
        "/system%2fconsole/bundles/12",
        "//system//console/bundles/12",
        "/x/%2e%2e/system/console/bundles/12",
        "/x/%2E%2E/%73ystem/console/bundles/12",
        "/x/.%2e/system/console/bundles/12",
        "/./system/./console/bundles/12",
        "/%2e/system/console/bundles/12",
        "/system;jsessionid=x/console/bundles/12",
        "/%73ystem;x=1/console;jsessionid=x/bundles/12",
        "/x/..;x=1/system/console/bundles/12",
        "/system%3Bx/console/bundles/12",
        "/SYSTEM/Console/bundles/12",
        "/%53YSTEM/%43onsole/configMgr/org.arflex.x",
        "\\system\\console/bundles/12",
        "/system%5cconsole/bundles/12",
        "/system/console",
        "/%73ystem/console"})
    void encodedSpellingsOfTheConsoleAreGuarded(String uri) throws Exception {
        assertRefused(run(raw("POST", uri, foreign())), "foreign Origin on " + uri);
        assertRefused(run(raw("POST", uri, h("Host", "127.0.0.1:8480"))), "no Origin nor Referer on " + uri);
        assertRefused(run(raw("POST", uri, h("Host", "127.0.0.1:8480", "Referer", "http://evil.example/x"))),
                "foreign Referer on " + uri);
        Outcome ok = run(raw("POST", uri, sameOrigin()));
        assertTrue(ok.passed, "same-origin request with token refused on " + uri + ": " + ok.reason);
        assertNull(ok.status);
        Outcome byReferer = run(raw("POST", uri, h("Host", "127.0.0.1:8480", "Referer", SELF + "/system/console/x",
                Csrf.HEADER, "t0ken")));
        assertTrue(byReferer.passed, "same-origin Referer refused on " + uri + ": " + byReferer.reason);
    }

    @ParameterizedTest(name = "{0}")
    @ValueSource(strings = {"POST", "PUT", "DELETE", "PATCH", "post", "PROPFIND"})
    void everyNonSafeMethodIsGuarded(String method) throws Exception {
        assertRefused(run(raw(method, "/%73ystem/console/bundles/12", foreign())), method);
    }

    @ParameterizedTest(name = "{0}")
    @ValueSource(strings = {"GET", "HEAD", "OPTIONS", "TRACE"})
    void safeMethodsPass(String method) throws Exception {
        assertTrue(run(raw(method, "/%73ystem/console/bundles/12", foreign())).passed, method);
    }

    /** Whatever the raw URI says, the context the dispatcher chose (the console's) decides. */
    @Test
    void theRoutedContextIsGuardedWhateverTheRawUri() throws Exception {
        assertRefused(run(request("POST", "/anything/else", "/system/console", "", "/bundles/12", foreign())),
                "console context");
        assertRefused(run(request("POST", "/anything/else", "", "/system/console", "/bundles/12", foreign())),
                "console servlet path");
        assertTrue(run(request("POST", "/anything/else", "/system/console", "", "/bundles/12", sameOrigin())).passed);
    }

    /** A non-safe request whose path cannot be read unambiguously is guarded too (fail closed). */
    @ParameterizedTest(name = "{0}")
    @ValueSource(strings = {
        "/%zzystem/console/bundles/12",
        "/%7",
        "/%25252525252573ystem/console",
        "/%C0%AFsystem/console",
        "/%FF/system/console",
        "/..%2fsystem/console",
        "/../system/console",
        "/a/%00/b",
        "/deploy/100%25"})
    void anUnreadablePathIsGuarded(String uri) throws Exception {
        Outcome o = run(raw("POST", uri, foreign()));
        assertRefused(o, uri);
        Outcome ok = run(raw("POST", uri, sameOrigin()));
        assertTrue(ok.passed, "same-origin request refused on " + uri + ": " + ok.reason);
    }

    @Test
    void theReasonSaysWhy() throws Exception {
        Outcome o = run(raw("POST", "/%73ystem/console/bundles/12", foreign()));
        assertTrue(o.reason.contains("evil.example"), o.reason);
        Outcome u = run(raw("POST", "/%zz/console", foreign()));
        assertTrue(u.reason.contains("cannot be normalised"), u.reason);
    }

    @ParameterizedTest(name = "{0}")
    @ValueSource(strings = {"/other/page", "/system/consolation/x", "/", "/systemconsole"})
    void pathsOutsideTheConsoleAreNotItsBusiness(String uri) throws Exception {
        assertTrue(run(raw("POST", uri, foreign())).passed, uri);
    }
}
