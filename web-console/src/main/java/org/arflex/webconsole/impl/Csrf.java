package org.arflex.webconsole.impl;

import jakarta.servlet.http.HttpServletRequest;
import jakarta.servlet.http.HttpSession;
import java.net.URI;
import java.nio.charset.StandardCharsets;
import java.security.MessageDigest;
import java.security.SecureRandom;
import java.util.Base64;
import java.util.Locale;

/**
 * Cross-site request forgery defence for every state-changing request of the console.
 *
 * <p>Two independent checks, both required: (1) the request comes from our own origin
 * ({@code Sec-Fetch-Site}, {@code Origin}, or else {@code Referer}, compared with the
 * {@code Host} the request was sent to, and that host must name this server, which also blocks
 * DNS rebinding); (2) it carries the per-session token in the {@code X-Arflex-Csrf} header,
 * compared in constant time. A request without a session has no token and is refused.
 */
final class Csrf {
    /** Header carrying the token on fetch() requests. */
    static final String HEADER = "X-Arflex-Csrf";
    /** Form field carrying the token on plain form posts. */
    static final String FIELD = "_csrf";
    private static final String ATTR = "org.arflex.webconsole.csrf";
    private static final SecureRandom RANDOM = new SecureRandom();

    private Csrf() {
    }

    /** The session's token, made on first use (creates the session). */
    static String token(HttpServletRequest req) {
        HttpSession s = req.getSession(true);
        synchronized (s) {
            Object t = s.getAttribute(ATTR);
            if (t instanceof String str) {
                return str;
            }
            byte[] b = new byte[32];
            RANDOM.nextBytes(b);
            String fresh = Base64.getUrlEncoder().withoutPadding().encodeToString(b);
            s.setAttribute(ATTR, fresh);
            return fresh;
        }
    }

    /** Null when the request may change state, otherwise why it is refused. */
    static String refusal(HttpServletRequest req) {
        String origin = sameOriginRefusal(req);
        if (origin != null) {
            return origin;
        }
        HttpSession s = req.getSession(false);
        Object expected = s == null ? null : s.getAttribute(ATTR);
        if (!(expected instanceof String exp)) {
            return "no CSRF token in this session: reload the page";
        }
        String given = req.getHeader(HEADER);
        if (given == null) {
            String ct = req.getContentType();
            if (ct != null && ct.toLowerCase(Locale.ROOT).startsWith("application/x-www-form-urlencoded")) {
                given = req.getParameter(FIELD);
            }
        }
        if (given == null || given.isEmpty()) {
            return "missing CSRF token (header " + HEADER + ")";
        }
        if (!MessageDigest.isEqual(exp.getBytes(StandardCharsets.UTF_8), given.getBytes(StandardCharsets.UTF_8))) {
            return "wrong CSRF token";
        }
        return null;
    }

    /**
     * Null when the request is same-origin, otherwise why not. Used alone (without the token)
     * by {@link CrossSiteFilter} for the Web Console's own pages.
     */
    static String sameOriginRefusal(HttpServletRequest req) {
        String host = req.getHeader("Host");
        if (host == null || !hostNamesThisServer(host, req)) {
            return "request addressed to host '" + host + "', which is not this console";
        }
        String expected = req.getScheme().toLowerCase(Locale.ROOT) + "://" + host.toLowerCase(Locale.ROOT);
        String site = req.getHeader("Sec-Fetch-Site");
        if (site != null && !site.equals("same-origin")) {
            return "cross-site request refused (Sec-Fetch-Site: " + site + ")";
        }
        String origin = req.getHeader("Origin");
        if (origin != null) {
            if (!origin.toLowerCase(Locale.ROOT).equals(expected)) {
                return "cross-origin request refused (Origin " + origin + " is not " + expected + ")";
            }
            return null;
        }
        String referer = req.getHeader("Referer");
        if (referer == null) {
            return "request without Origin or Referer refused";
        }
        String r = referer.toLowerCase(Locale.ROOT);
        if (!(r.equals(expected) || r.startsWith(expected + "/"))) {
            return "cross-origin request refused (Referer is not " + expected + ")";
        }
        return null;
    }

    private static boolean hostNamesThisServer(String hostHeader, HttpServletRequest req) {
        String h;
        try {
            URI u = new URI("http://" + hostHeader + "/");
            h = u.getHost();
            if (h == null || (u.getPort() != -1 && u.getPort() != req.getLocalPort())) {
                return false;
            }
        } catch (Exception e) {
            return false;
        }
        h = h.toLowerCase(Locale.ROOT);
        if (h.startsWith("[") && h.endsWith("]")) {
            h = h.substring(1, h.length() - 1);
        }
        String local = req.getLocalAddr();
        return h.equals("localhost") || h.equals(local) || h.equals(req.getLocalName());
    }
}
