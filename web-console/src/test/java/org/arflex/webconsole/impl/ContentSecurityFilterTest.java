package org.arflex.webconsole.impl;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertNotNull;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import jakarta.servlet.FilterChain;
import jakarta.servlet.ServletOutputStream;
import jakarta.servlet.WriteListener;
import jakarta.servlet.http.HttpServletRequest;
import jakarta.servlet.http.HttpServletResponse;
import java.io.ByteArrayOutputStream;
import java.io.InputStream;
import java.io.PrintWriter;
import java.io.StringWriter;
import java.lang.reflect.Proxy;
import java.nio.charset.StandardCharsets;
import java.util.ArrayList;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import java.util.regex.Matcher;
import java.util.regex.Pattern;
import org.junit.jupiter.api.Test;

/**
 * The policy on every response, and the nonce in every script tag of an HTML page (issue 16,
 * finding 2: markup from a manifest header must not run in the console).
 */
class ContentSecurityFilterTest {

    /** A response that keeps what was set and written. */
    private static final class Captured {
        final Map<String, String> headers = new LinkedHashMap<>();
        final StringWriter text = new StringWriter();
        final ByteArrayOutputStream bytes = new ByteArrayOutputStream();
        String contentType;
        Long contentLength;

        HttpServletResponse proxy() {
            ServletOutputStream out = new ServletOutputStream() {
                @Override
                public void write(int b) {
                    bytes.write(b);
                }

                @Override
                public boolean isReady() {
                    return true;
                }

                @Override
                public void setWriteListener(WriteListener l) {
                }
            };
            PrintWriter w = new PrintWriter(text);
            return (HttpServletResponse) Proxy.newProxyInstance(getClass().getClassLoader(),
                    new Class<?>[] {HttpServletResponse.class}, (p, m, a) -> switch (m.getName()) {
                        case "setHeader" -> {
                            headers.put(((String) a[0]).toLowerCase(), (String) a[1]);
                            yield null;
                        }
                        case "getHeader" -> headers.get(((String) a[0]).toLowerCase());
                        case "setContentType" -> {
                            contentType = (String) a[0];
                            yield null;
                        }
                        case "getContentType" -> contentType;
                        case "setContentLength" -> {
                            contentLength = (long) (Integer) a[0];
                            yield null;
                        }
                        case "setContentLengthLong" -> {
                            contentLength = (Long) a[0];
                            yield null;
                        }
                        case "reset" -> {
                            headers.clear();
                            contentType = null;
                            yield null;
                        }
                        case "getWriter" -> w;
                        case "getOutputStream" -> out;
                        case "hashCode" -> System.identityHashCode(p);
                        case "equals" -> p == a[0];
                        default -> null;
                    });
        }
    }

    private static HttpServletRequest request() {
        return request("/system/console/arflex-cell");
    }

    private static HttpServletRequest request(String uri) {
        return (HttpServletRequest) Proxy.newProxyInstance(ContentSecurityFilterTest.class.getClassLoader(),
                new Class<?>[] {HttpServletRequest.class}, (p, m, a) -> switch (m.getName()) {
                    case "getMethod" -> "GET";
                    case "getRequestURI" -> uri;
                    default -> null;
                });
    }

    private static String scriptSrc(String uri) throws Exception {
        Captured c = new Captured();
        new ContentSecurityFilter().doFilter(request(uri), c.proxy(), (rq, rs) -> { });
        return c.headers.get("content-security-policy").split("script-src ")[1].split(";")[0];
    }

    private static String nonceOf(String policy) {
        Matcher m = Pattern.compile("'nonce-([A-Za-z0-9_-]+)'").matcher(policy);
        assertTrue(m.find(), policy);
        return m.group(1);
    }

    @Test
    void everyResponseGetsAFreshPolicyWithoutUnsafeInlineOrEval() throws Exception {
        List<String> nonces = new ArrayList<>();
        for (int i = 0; i < 2; i++) {
            Captured c = new Captured();
            new ContentSecurityFilter().doFilter(request(), c.proxy(), (rq, rs) -> { });
            String csp = c.headers.get("content-security-policy");
            assertNotNull(csp);
            String scripts = csp.split("script-src ")[1].split(";")[0];
            assertFalse(scripts.contains("'unsafe-inline'"), scripts);
            assertFalse(scripts.contains("'unsafe-eval'"), scripts);
            assertFalse(scripts.contains("*") || scripts.contains("http"), "no other origin: " + scripts);
            for (String d : List.of("default-src 'self'", "object-src 'none'", "img-src 'self' data:", "connect-src 'self'",
                    "form-action 'self'", "frame-ancestors 'self'", "base-uri 'self'")) {
                assertTrue(csp.contains(d), d + " in " + csp);
            }
            assertEquals("nosniff", c.headers.get("x-content-type-options"));
            assertEquals("SAMEORIGIN", c.headers.get("x-frame-options"));
            nonces.add(nonceOf(csp));
        }
        assertFalse(nonces.get(0).equals(nonces.get(1)), "a nonce per response");
    }

    @Test
    void evalOnlyOnTheWebConsolesOwnPagesAndInlineNowhere() throws Exception {
        for (String ours : new String[] {"/system/console/arflex-cell", "/system/console/arflex-deploy/api/install",
                "/%73ystem/console/arflex-cell", "/system/console/%zz", "/system/../../x"}) {
            assertFalse(scriptSrc(ours).contains("'unsafe-eval'"), ours);
        }
        for (String felix : new String[] {"/system/console/configMgr", "/system/console/bundles/12",
                "/system/console/res/lib/jquery.tablesorter-2.0.3.js"}) {
            String s = scriptSrc(felix);
            assertTrue(s.contains("'unsafe-eval'"), felix);
            assertFalse(s.contains("'unsafe-inline'"), felix);
        }
    }

    @Test
    void theScriptsOfAnHtmlPageCarryTheNonceOfItsPolicy() throws Exception {
        Captured c = new Captured();
        FilterChain page = (rq, rs) -> {
            HttpServletResponse r = (HttpServletResponse) rs;
            r.setContentType("text/html; charset=utf-8");
            r.setContentLength(10);
            PrintWriter w = r.getWriter();
            w.print("<head><script>appRoot = \"/system/console\";</script><script src=\"/a.js\"></script></head>");
            w.print("<body><div id='x'></div><scr");
            w.print("ipt>var d = {\"v\":\"<img src=x onerror=alert(1)>\"};</script></body>");
        };
        new ContentSecurityFilter().doFilter(request(), c.proxy(), page);
        String n = nonceOf(c.headers.get("content-security-policy"));
        assertEquals("<head><script nonce=" + n + ">appRoot = \"/system/console\";</script><script nonce=" + n
                + " src=\"/a.js\"></script></head><body><div id='x'></div><script nonce=" + n
                + ">var d = {\"v\":\"<img src=x onerror=alert(1)>\"};</script></body>", c.text.toString());
        assertNull(c.contentLength, "the length of a rewritten page is not the one the servlet set");
    }

    @Test
    void jsonAndScriptFilesPassUntouchedWithTheirLength() throws Exception {
        Captured c = new Captured();
        byte[] body = "{\"s\":\"<script>\"}".getBytes(StandardCharsets.UTF_8);
        new ContentSecurityFilter().doFilter(request(), c.proxy(), (rq, rs) -> {
            HttpServletResponse r = (HttpServletResponse) rs;
            r.setContentType("application/json");
            r.setContentLength(body.length);
            r.getOutputStream().write(body);
        });
        assertEquals("{\"s\":\"<script>\"}", c.bytes.toString(StandardCharsets.UTF_8));
        assertEquals(body.length, c.contentLength);
    }

    @Test
    void anHtmlPageWrittenAsBytesIsRewrittenToo() throws Exception {
        Captured c = new Captured();
        new ContentSecurityFilter().doFilter(request(), c.proxy(), (rq, rs) -> {
            rs.setContentType("text/html");
            rs.getOutputStream().write("<script>x()</script>".getBytes(StandardCharsets.UTF_8));
        });
        String n = nonceOf(c.headers.get("content-security-policy"));
        assertEquals("<script nonce=" + n + ">x()</script>", c.bytes.toString(StandardCharsets.UTF_8));
    }

    @Test
    void aResetResponseKeepsItsPolicy() throws Exception {
        Captured c = new Captured();
        new ContentSecurityFilter().doFilter(request(), c.proxy(), (rq, rs) -> rs.reset());
        assertNotNull(c.headers.get("content-security-policy"));
    }

    @Test
    void theAllowedHandlersAreExactlyThoseOfTheWebConsolesSystemPage() throws Exception {
        // The Web Console 5.0.18 jar is on the test class path (provided scope): its template
        // holds the handlers as they must hash. A new Web Console that changes them fails here.
        String template;
        try (InputStream in = org.apache.felix.webconsole.servlet.AbstractServlet.class.getClassLoader()
                .getResourceAsStream("templates/vmstat.html")) {
            assertNotNull(in, "templates/vmstat.html of the Web Console");
            template = new String(in.readAllBytes(), StandardCharsets.UTF_8);
        }
        Matcher m = Pattern.compile("onclick=\"([^\"]*)\"").matcher(template);
        List<String> handlers = new ArrayList<>();
        while (m.find()) {
            handlers.add(m.group(1).replace("${pluginRoot}", CrossSiteFilter.CONSOLE_ROOT + "/vmstat"));
        }
        assertEquals(ContentSecurityFilter.ALLOWED_HANDLERS, handlers);
        String csp = ContentSecurityFilter.policy("n", false);
        for (String h : handlers) {
            assertTrue(csp.contains("'sha256-" + ContentSecurityFilter.sha256(h) + "'"), h);
        }
        // The hash is the CSP one: SHA-256 of the UTF-8 text, base64 (a known value).
        assertEquals("ungWv48Bz+pBQUDeXa4iI7ADYaOWF3qctBD/YfIAFa0=", ContentSecurityFilter.sha256("abc"));
    }
}
