package org.arflex.webconsole.impl;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import com.fasterxml.jackson.databind.ObjectMapper;
import jakarta.servlet.ReadListener;
import jakarta.servlet.ServletInputStream;
import jakarta.servlet.ServletOutputStream;
import jakarta.servlet.WriteListener;
import jakarta.servlet.http.HttpServletRequest;
import jakarta.servlet.http.HttpServletResponse;
import java.io.ByteArrayInputStream;
import java.io.ByteArrayOutputStream;
import java.lang.reflect.Proxy;
import java.nio.charset.StandardCharsets;
import java.util.HashMap;
import java.util.List;
import java.util.Map;
import org.junit.jupiter.api.Test;

/**
 * What every page backend's endpoint shares: the JSON answer with its headers, error answers
 * naming what is wrong (recorded for the audit log), the CSRF gate, the body limit, and the
 * route table.
 */
class ApiCallTest {
    private static final ObjectMapper JSON = new ObjectMapper();

    private final Map<String, Object> attributes = new HashMap<>();
    private final Map<String, List<String>> headers = new HashMap<>();
    private final ByteArrayOutputStream written = new ByteArrayOutputStream();
    private int status;
    private String contentType;

    private HttpServletRequest request(Map<String, String> params, byte[] body) {
        ByteArrayInputStream in = new ByteArrayInputStream(body);
        ServletInputStream stream = new ServletInputStream() {
            @Override
            public boolean isFinished() {
                return in.available() == 0;
            }

            @Override
            public boolean isReady() {
                return true;
            }

            @Override
            public void setReadListener(ReadListener l) {
            }

            @Override
            public int read() {
                return in.read();
            }
        };
        return (HttpServletRequest) Proxy.newProxyInstance(getClass().getClassLoader(),
                new Class<?>[] {HttpServletRequest.class}, (p, m, a) -> switch (m.getName()) {
                    case "getParameter" -> params.get((String) a[0]);
                    case "getInputStream" -> stream;
                    case "setAttribute" -> attributes.put((String) a[0], a[1]);
                    case "getAttribute" -> attributes.get((String) a[0]);
                    case "getMethod" -> "POST";
                    case "getScheme" -> "http";
                    default -> null;
                });
    }

    private HttpServletResponse response() {
        ServletOutputStream out = new ServletOutputStream() {
            @Override
            public boolean isReady() {
                return true;
            }

            @Override
            public void setWriteListener(WriteListener l) {
            }

            @Override
            public void write(int b) {
                written.write(b);
            }
        };
        return (HttpServletResponse) Proxy.newProxyInstance(getClass().getClassLoader(),
                new Class<?>[] {HttpServletResponse.class}, (p, m, a) -> switch (m.getName()) {
                    case "setStatus" -> {
                        status = (Integer) a[0];
                        yield null;
                    }
                    case "setContentType" -> {
                        contentType = (String) a[0];
                        yield null;
                    }
                    case "setHeader" -> headers.put((String) a[0], new java.util.ArrayList<>(List.of((String) a[1])));
                    case "addHeader" -> headers.computeIfAbsent((String) a[0], k -> new java.util.ArrayList<>())
                            .add((String) a[1]);
                    case "getOutputStream" -> out;
                    default -> null;
                });
    }

    private ApiCall call(Map<String, String> params, byte[] body) {
        return new ApiCall(request(params, body), response(), JSON);
    }

    private Map<?, ?> answer() throws Exception {
        return JSON.readValue(written.toByteArray(), Map.class);
    }

    @Test
    void anAnswerIsJsonNeverCachedOrSniffed() throws Exception {
        Routes routes = new Routes().get("echo", c -> Map.of("name", c.name(), "port", c.param("port")));
        call(Map.of("name", "sample-counter", "port", "count"), new byte[0]).answer(c -> routes.answerGet("echo", c));
        assertEquals(200, status);
        assertEquals("application/json", contentType);
        assertEquals(List.of("nosniff"), headers.get("X-Content-Type-Options"));
        assertTrue(headers.get("Cache-Control").contains("no-store"), headers.toString());
        assertEquals(Map.of("name", "sample-counter", "port", "count"), answer());
        assertFalse(attributes.containsKey(AuditFilter.REASON));
    }

    @Test
    void anUnknownEndpointIs404NamingIt() throws Exception {
        Routes routes = new Routes().get("cell", c -> Map.of());
        call(Map.of(), new byte[0]).answer(c -> routes.answerPost("cell", c));
        assertEquals(404, status);
        assertEquals(Map.of("error", "no endpoint /api/cell"), answer());
        assertEquals("no endpoint /api/cell", attributes.get(AuditFilter.REASON));
    }

    @Test
    void aRefusalKeepsItsStatusAndAFailureIs500WithItsClass() throws Exception {
        call(Map.of(), new byte[0]).answer(c -> {
            throw new HttpError(409, "component 'x' has no RT half running (no histogram)");
        });
        assertEquals(409, status);
        assertEquals(Map.of("error", "component 'x' has no RT half running (no histogram)"), answer());

        written.reset();
        call(Map.of(), new byte[0]).answer(c -> {
            throw new IllegalStateException("boom");
        });
        assertEquals(500, status);
        assertEquals(Map.of("error", "IllegalStateException: boom"), answer());
        assertEquals("IllegalStateException: boom", attributes.get(AuditFilter.REASON));
    }

    @Test
    void aStateChangeWithoutOriginOrTokenIsRefused403() throws Exception {
        assertTrue(call(Map.of(), new byte[0]).refusedCrossSite());
        assertEquals(403, status);
        assertEquals(Map.of("error", attributes.get(AuditFilter.REASON)), answer());
    }

    @Test
    void aTextBodyIsReadUpTo1MiB() throws Exception {
        byte[] xml = "<contract/>".getBytes(StandardCharsets.UTF_8);
        assertEquals("<contract/>", call(Map.of(), xml).text());
        HttpError e = assertThrows(HttpError.class, () -> call(Map.of(), new byte[(1 << 20) + 1]).text());
        assertEquals(413, e.status);
        assertEquals("contract larger than 1 MiB refused", e.getMessage());
    }

    @Test
    void anEndpointClaimedTwiceIsAnErrorAtActivation() {
        Routes routes = new Routes().get("cell", c -> Map.of());
        assertThrows(IllegalStateException.class, () -> routes.add(new Routes().get("cell", c -> Map.of())));
        routes.add(new Routes().post("cell", c -> Map.of()));
    }
}
