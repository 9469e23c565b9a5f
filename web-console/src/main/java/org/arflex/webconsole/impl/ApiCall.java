package org.arflex.webconsole.impl;

import com.fasterxml.jackson.databind.ObjectMapper;
import jakarta.servlet.http.HttpServletRequest;
import jakarta.servlet.http.HttpServletResponse;
import java.io.IOException;
import java.io.InputStream;
import java.io.OutputStream;
import java.nio.charset.StandardCharsets;
import java.util.Map;
import org.apache.felix.webconsole.servlet.AbstractServlet;

/**
 * One call of a console page's JSON API, and what every page backend shares to serve it: the
 * request's parameters and body, the CSRF gate of a state change, the answer written as JSON and
 * the error answer {@code {"error": "..."}} naming what is wrong (also recorded for the
 * {@link AuditFilter}).
 */
final class ApiCall {
    /** Largest text body (a contract) read. */
    private static final int MAX_TEXT = 1 << 20;

    private final HttpServletRequest req;
    private final HttpServletResponse resp;
    private final ObjectMapper json;
    private String name;

    ApiCall(HttpServletRequest req, HttpServletResponse resp, ObjectMapper json) {
        this.req = req;
        this.resp = resp;
        this.json = json;
    }

    String param(String key) {
        return req.getParameter(key);
    }

    /** The {@code name} parameter (the component, contract, ...), read before the route ran. */
    String name() {
        return name;
    }

    /** The authenticated user, as the audit log names it (null when unknown). */
    String user() {
        return AuditFilter.user(req);
    }

    /** The client's address. */
    String remote() {
        return req.getRemoteAddr();
    }

    /** The request body as it comes; the caller closes it. */
    InputStream body() throws IOException {
        return req.getInputStream();
    }

    /** The request body as UTF-8 text, at most 1 MiB. */
    String text() throws IOException, HttpError {
        try (InputStream in = req.getInputStream()) {
            byte[] b = in.readNBytes(MAX_TEXT + 1);
            if (b.length > MAX_TEXT) {
                throw new HttpError(413, "contract larger than 1 MiB refused");
            }
            return new String(b, StandardCharsets.UTF_8);
        }
    }

    /** The CSRF gate ({@link Csrf}) of a state change: true when it refused and answered 403. */
    boolean refusedCrossSite() throws IOException {
        String why = Csrf.refusal(req);
        if (why == null) {
            return false;
        }
        req.setAttribute(AuditFilter.REFUSED, Boolean.TRUE);
        refuse(403, why);
        return true;
    }

    /** Answers with what {@code route} returns, or with the error naming what is wrong. */
    void answer(Routes.Route route) throws IOException {
        try {
            // Read before the route, which may read the body as a stream (a form body is parsed here).
            name = req.getParameter("name");
            send(200, route.answer(this));
        } catch (HttpError e) {
            refuse(e.status, e.getMessage());
        } catch (RuntimeException e) {
            refuse(500, e.getClass().getSimpleName() + ": " + e.getMessage());
        }
    }

    /** An error answer whose reason the audit log records. */
    void refuse(int status, String why) throws IOException {
        req.setAttribute(AuditFilter.REASON, why);
        send(status, Map.of("error", why));
    }

    /** A JSON answer, never cached or sniffed. */
    void send(int status, Object body) throws IOException {
        AbstractServlet.setNoCache(resp);
        resp.setStatus(status);
        resp.setContentType("application/json");
        resp.setCharacterEncoding("UTF-8");
        resp.setHeader("X-Content-Type-Options", "nosniff");
        byte[] b = json.writeValueAsBytes(body);
        resp.setContentLength(b.length);
        try (OutputStream out = resp.getOutputStream()) {
            out.write(b);
        }
    }
}
