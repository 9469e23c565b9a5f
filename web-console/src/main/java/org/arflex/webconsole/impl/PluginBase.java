package org.arflex.webconsole.impl;

import jakarta.servlet.ServletException;
import jakarta.servlet.http.HttpServletRequest;
import jakarta.servlet.http.HttpServletResponse;
import java.io.IOException;
import java.io.OutputStream;
import java.io.PrintWriter;
import java.nio.charset.StandardCharsets;
import java.util.Map;
import java.util.concurrent.atomic.AtomicInteger;
import org.apache.felix.webconsole.servlet.AbstractServlet;
import org.apache.felix.webconsole.servlet.ServletConstants;
import org.owasp.encoder.Encode;

/**
 * Common base of the console pages. Under {@code /system/console/<label>}:
 * <ul>
 * <li>{@code GET} with no further path: the page (the Web Console draws its frame around
 * {@link #renderContent}); the page script then reads the JSON endpoints;
 * <li>{@code GET /res/...}: static files of this bundle (our scripts and the vendored
 * libraries);
 * <li>{@code GET /api/...}: JSON; {@code GET /api/stream}: server-sent events;
 * <li>{@code POST /api/...}: state changes, each checked by {@link Csrf} first.
 * </ul>
 * The page HTML holds no data: scripts fill it through {@code textContent}, and the few
 * server-written values are encoded for their context with the OWASP encoder.
 */
abstract class PluginBase extends AbstractServlet {
    private static final long serialVersionUID = 1L;
    /** Most live streams open at once (each holds one HTTP thread). */
    static final int MAX_STREAMS = 8;
    /** A stream ends after this long; EventSource reconnects by itself. */
    static final long STREAM_MS = 5 * 60_000L;
    private static final AtomicInteger STREAMS = new AtomicInteger();

    abstract Backend backend();

    /** The JSON endpoints this page serves: every page backend's (see {@link Backend}). */
    Routes routes() {
        return backend().routes();
    }

    /** The page name, also the name of its script ({@code res/arflex/<page>.js}). */
    abstract String page();

    /** The label under the console root. */
    abstract String label();

    /** Vendored scripts the page needs, under {@code res/vendor/}. */
    String[] vendorScripts() {
        return new String[0];
    }

    String[] vendorStyles() {
        return new String[0];
    }

    private String route(HttpServletRequest req) {
        String p = req.getPathInfo();
        if (p == null) {
            return "";
        }
        String prefix = "/" + label();
        return p.startsWith(prefix) ? p.substring(prefix.length()) : p;
    }

    @Override
    protected void doGet(HttpServletRequest req, HttpServletResponse resp) throws ServletException, IOException {
        String r = route(req);
        if (r.startsWith("/res/")) {
            if (getResource(req.getPathInfo()) == null) {
                resp.sendError(404, "no resource " + r);
            } else {
                spoolResource(req, resp);
            }
            return;
        }
        if (r.equals("/api/stream")) {
            stream(req, resp);
            return;
        }
        if (r.startsWith("/api/")) {
            new ApiCall(req, resp, backend().json).answer(call -> routes().answerGet(r.substring(5), call));
            return;
        }
        // Anything else: leave the response untouched, the Web Console renders the page.
    }

    @Override
    protected void doPost(HttpServletRequest req, HttpServletResponse resp) throws IOException {
        String r = route(req);
        ApiCall api = new ApiCall(req, resp, backend().json);
        if (api.refusedCrossSite()) {
            return;
        }
        if (!r.startsWith("/api/")) {
            api.refuse(404, "no endpoint " + r);
            return;
        }
        api.answer(call -> routes().answerPost(r.substring(5), call));
    }

    /**
     * Server-sent events: one frame per sampler period for the named component, with the
     * values of the output ports listed in {@code ports} (comma separated, at most
     * {@link Sampler#MAX_PORTS}).
     */
    private void stream(HttpServletRequest req, HttpServletResponse resp) throws IOException {
        String name = req.getParameter("name");
        ApiCall api = new ApiCall(req, resp, backend().json);
        Sampler.Key key;
        try {
            Names.checkName(name);
            key = new Sampler.Key(name, Names.portList(req.getParameter("ports")));
        } catch (HttpError e) {
            api.send(400, Map.of("error", e.getMessage()));
            return;
        }
        if (STREAMS.incrementAndGet() > MAX_STREAMS) {
            STREAMS.decrementAndGet();
            api.send(503, Map.of("error", "too many live streams open (" + MAX_STREAMS + ")"));
            return;
        }
        Sampler s = backend().sampler;
        try {
            s.subscribe(key);
        } catch (IllegalStateException e) {
            STREAMS.decrementAndGet();
            api.send(503, Map.of("error", e.getMessage()));
            return;
        }
        try {
            setNoCache(resp);
            resp.setStatus(200);
            resp.setContentType("text/event-stream");
            resp.setCharacterEncoding("UTF-8");
            OutputStream out = resp.getOutputStream();
            out.write("retry: 2000\n\n".getBytes(StandardCharsets.UTF_8));
            out.flush();
            long seq = 0;
            long end = System.currentTimeMillis() + STREAM_MS;
            while (System.currentTimeMillis() < end) {
                Sampler.Frame f = s.awaitAfter(seq, 1000);
                String line;
                if (f == null) {
                    line = ": idle\n\n";
                } else if (!f.sampled().contains(key)) {
                    // Read before this stream subscribed: not "gone", just not sampled yet.
                    seq = f.seq();
                    continue;
                } else {
                    seq = f.seq();
                    Object sample = f.byKey().get(key);
                    line = "data: " + backend().json.writeValueAsString(
                            sample == null ? Map.of("gone", true) : sample) + "\n\n";
                }
                out.write(line.getBytes(StandardCharsets.UTF_8));
                out.flush();
            }
        } catch (IOException e) {
            // The browser went away: end quietly.
        } catch (InterruptedException e) {
            Thread.currentThread().interrupt();
        } finally {
            s.unsubscribe(key);
            STREAMS.decrementAndGet();
        }
    }

    @Override
    public void renderContent(HttpServletRequest req, HttpServletResponse resp) throws IOException {
        String appRoot = String.valueOf(req.getAttribute(ServletConstants.ATTR_APP_ROOT));
        String root = appRoot + "/" + label();
        String token = Csrf.token(req);
        PrintWriter w = resp.getWriter();
        w.println("<link rel='stylesheet' href='" + Encode.forHtmlAttribute(root + "/res/arflex/arflex.css") + "'>");
        for (String css : vendorStyles()) {
            w.println("<link rel='stylesheet' href='" + Encode.forHtmlAttribute(root + "/res/vendor/" + css) + "'>");
        }
        w.println("<div id='arflex-app' class='arflex' data-page='" + Encode.forHtmlAttribute(page())
                + "' data-root='" + Encode.forHtmlAttribute(root)
                + "' data-app-root='" + Encode.forHtmlAttribute(appRoot)
                + "' data-csrf='" + Encode.forHtmlAttribute(token) + "'>");
        w.println("<noscript>This page needs JavaScript.</noscript></div>");
        for (String js : vendorScripts()) {
            w.println("<script src='" + Encode.forHtmlAttribute(root + "/res/vendor/" + js) + "'></script>");
        }
        w.println("<script src='" + Encode.forHtmlAttribute(root + "/res/arflex/arflex.js") + "'></script>");
        w.println("<script src='" + Encode.forHtmlAttribute(root + "/res/arflex/" + page() + ".js") + "'></script>");
    }
}
