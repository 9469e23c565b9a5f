package org.arflex.webconsole.impl;

import static org.junit.jupiter.api.Assertions.assertNotNull;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import jakarta.servlet.http.HttpServletRequest;
import jakarta.servlet.http.HttpSession;
import java.lang.reflect.Proxy;
import java.util.HashMap;
import java.util.Map;
import org.junit.jupiter.api.Test;

/** The CSRF rules, on requests built by hand (no servlet container needed). */
class CsrfTest {
    private final Map<String, Object> sessionAttrs = new HashMap<>();
    private final HttpSession session = (HttpSession) Proxy.newProxyInstance(getClass().getClassLoader(),
            new Class<?>[] {HttpSession.class}, (p, m, a) -> switch (m.getName()) {
                case "getAttribute" -> sessionAttrs.get((String) a[0]);
                case "setAttribute" -> sessionAttrs.put((String) a[0], a[1]);
                default -> null;
            });

    private HttpServletRequest request(Map<String, String> headers, boolean hasSession) {
        return (HttpServletRequest) Proxy.newProxyInstance(getClass().getClassLoader(),
                new Class<?>[] {HttpServletRequest.class}, (p, m, a) -> switch (m.getName()) {
                    case "getHeader" -> headers.get((String) a[0]);
                    case "getScheme" -> "http";
                    case "getLocalPort" -> 8480;
                    case "getLocalAddr" -> "127.0.0.1";
                    case "getLocalName" -> "localhost";
                    case "getSession" -> (a == null || a.length == 0 || (Boolean) a[0] || hasSession) ? session : null;
                    case "getContentType" -> headers.get("Content-Type");
                    case "getParameter" -> null;
                    default -> null;
                });
    }

    private String token() {
        return Csrf.token(request(Map.of(), true));
    }

    private static Map<String, String> h(String... kv) {
        Map<String, String> m = new HashMap<>();
        for (int i = 0; i < kv.length; i += 2) {
            m.put(kv[i], kv[i + 1]);
        }
        return m;
    }

    @Test
    void sameOriginWithTheSessionTokenIsAccepted() {
        String t = token();
        assertNull(Csrf.refusal(request(h("Host", "127.0.0.1:8480", "Origin", "http://127.0.0.1:8480",
                "Sec-Fetch-Site", "same-origin", Csrf.HEADER, t), true)));
        assertNull(Csrf.refusal(request(h("Host", "localhost:8480", "Referer", "http://localhost:8480/system/console/x",
                Csrf.HEADER, t), true)));
    }

    @Test
    void missingOrWrongTokenIsRefused() {
        String t = token();
        assertTrue(Csrf.refusal(request(h("Host", "127.0.0.1:8480", "Origin", "http://127.0.0.1:8480"), true))
                .contains("missing CSRF token"));
        assertTrue(Csrf.refusal(request(h("Host", "127.0.0.1:8480", "Origin", "http://127.0.0.1:8480",
                Csrf.HEADER, t + "x"), true)).contains("wrong CSRF token"));
        assertTrue(Csrf.refusal(request(h("Host", "127.0.0.1:8480", "Origin", "http://127.0.0.1:8480",
                Csrf.HEADER, t), false)).contains("no CSRF token in this session"));
    }

    @Test
    void crossOriginIsRefusedEvenWithTheToken() {
        String t = token();
        assertNotNull(Csrf.refusal(request(h("Host", "127.0.0.1:8480", "Origin", "http://evil.example",
                Csrf.HEADER, t), true)));
        assertNotNull(Csrf.refusal(request(h("Host", "127.0.0.1:8480", "Sec-Fetch-Site", "cross-site",
                "Origin", "http://127.0.0.1:8480", Csrf.HEADER, t), true)));
        assertNotNull(Csrf.refusal(request(h("Host", "127.0.0.1:8480", "Referer", "http://127.0.0.1:8480.evil.example/",
                Csrf.HEADER, t), true)));
        assertTrue(Csrf.refusal(request(h("Host", "127.0.0.1:8480", Csrf.HEADER, t), true))
                .contains("without Origin or Referer"));
    }

    @Test
    void aRebindedHostNameIsRefused() {
        String t = token();
        // DNS rebinding: the attacker's name resolves to 127.0.0.1, Origin and Host agree.
        assertTrue(Csrf.refusal(request(h("Host", "attacker.example:8480", "Origin", "http://attacker.example:8480",
                Csrf.HEADER, t), true)).contains("not this console"));
        assertNotNull(Csrf.refusal(request(h("Host", "127.0.0.1:9999", "Origin", "http://127.0.0.1:9999",
                Csrf.HEADER, t), true)));
    }
}
