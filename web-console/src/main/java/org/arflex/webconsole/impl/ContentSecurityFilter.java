package org.arflex.webconsole.impl;

import jakarta.servlet.Filter;
import jakarta.servlet.FilterChain;
import jakarta.servlet.ServletException;
import jakarta.servlet.ServletOutputStream;
import jakarta.servlet.ServletRequest;
import jakarta.servlet.ServletResponse;
import jakarta.servlet.http.HttpServletRequest;
import jakarta.servlet.http.HttpServletResponse;
import jakarta.servlet.http.HttpServletResponseWrapper;
import java.io.IOException;
import java.io.PrintWriter;
import java.nio.charset.StandardCharsets;
import java.security.MessageDigest;
import java.security.NoSuchAlgorithmException;
import java.util.Base64;
import java.util.List;
import java.util.Locale;
import org.osgi.service.component.annotations.Component;

/**
 * A Content-Security-Policy on every response of the HTTP service (the console is all it
 * serves), so that markup which reaches a page (issue 16: a bundle's {@code Bundle-Vendor}
 * {@code <img src=x onerror=...>}, put into the bundle details by Felix's script through
 * {@code innerHTML}) cannot run script, load from or send to another origin.
 *
 * <p>The policy ({@link #policy}): scripts only from this origin or carrying this response's
 * nonce ({@link ScriptNonce} gives it to every {@code <script} tag the server writes), never
 * {@code 'unsafe-inline'}; the only inline event handlers allowed are the Web Console's three
 * fixed ones on its System Information page (the confirmations before the framework is stopped
 * or restarted), by hash ({@code 'unsafe-hashes'}); images, fonts, fetches, form targets and
 * frames of this origin only; no plugins; no {@code <base>} elsewhere. Styles may be inline
 * ({@code style=} attributes are all over the Web Console's markup; CSS cannot run script in a
 * current browser).
 *
 * <p>{@code 'unsafe-eval'} only on the Web Console's own pages, never on ours
 * ({@code /system/console/arflex-*}): its tablesorter builds the sort comparator with
 * {@code eval} while a table is set up (without it the Configuration page lists no
 * configuration at all), and its multi-file upload is a packed script unpacked with
 * {@code eval}. Eval does not let injected markup run: markup cannot call it, only a running
 * script can, and no script of the Web Console evaluates page data (docs/DECISIONS.md D15).
 * What stays broken there: the bundle links of the Licenses page ({@code javascript:} URLs).
 */
@Component(service = Filter.class, property = {
    "osgi.http.whiteboard.filter.pattern=/*",
    "osgi.http.whiteboard.context.select=(osgi.http.whiteboard.context.name=*)",
    "osgi.http.whiteboard.filter.name=arflex-content-security",
    "service.ranking:Integer=900"})
public class ContentSecurityFilter implements Filter {
    /**
     * The inline event handlers of the Web Console's templates/vmstat.html (5.0.18) that stay
     * allowed, exactly as written there; {@code abort} names the page's root.
     */
    static final List<String> ALLOWED_HANDLERS = List.of(
            "return confirm('This will stop and restart the framework and all bundles. Please confirm to continue.');",
            "return confirm('This will stop the framework and all bundles. Please confirm to continue.')",
            "abort('" + CrossSiteFilter.CONSOLE_ROOT + "/vmstat')");
    private static final String HANDLER_HASHES = hashes(ALLOWED_HANDLERS);
    /** Where our pages are: the strict policy, without eval. */
    static final String OURS = CrossSiteFilter.CONSOLE_ROOT + "/arflex-";

    @Override
    public void doFilter(ServletRequest request, ServletResponse response, FilterChain chain)
            throws IOException, ServletException {
        if (!(response instanceof HttpServletResponse resp)) {
            chain.doFilter(request, response);
            return;
        }
        String nonce = ScriptNonce.fresh();
        boolean ours = request instanceof HttpServletRequest req && ours(req);
        setHeaders(resp, nonce, !ours);
        NonceResponse wrapped = new NonceResponse(resp, nonce, !ours);
        try {
            chain.doFilter(request, wrapped);
        } finally {
            wrapped.finish();
        }
    }

    /**
     * True for our pages and endpoints ({@value #OURS}...), and for a path that cannot be
     * read (the stricter policy then).
     */
    static boolean ours(HttpServletRequest req) {
        String uri = req.getRequestURI();
        if (uri == null) {
            return true;
        }
        try {
            return ConsolePath.under(ConsolePath.normalise(uri), OURS);
        } catch (IllegalArgumentException e) {
            return true;
        }
    }

    static void setHeaders(HttpServletResponse resp, String nonce, boolean eval) {
        resp.setHeader("Content-Security-Policy", policy(nonce, eval));
        resp.setHeader("X-Content-Type-Options", "nosniff");
        resp.setHeader("X-Frame-Options", "SAMEORIGIN");
        resp.setHeader("Referrer-Policy", "same-origin");
    }

    /**
     * The policy for a response whose scripts carry {@code nonce}; {@code eval} for the Web
     * Console's own pages.
     */
    static String policy(String nonce, boolean eval) {
        return "default-src 'self'; "
                + "script-src 'self' 'nonce-" + nonce + "' 'unsafe-hashes' " + HANDLER_HASHES
                + (eval ? " 'unsafe-eval'" : "") + " 'report-sample'; "
                + "style-src 'self' 'unsafe-inline'; "
                + "img-src 'self' data:; "
                + "font-src 'self' data:; "
                + "connect-src 'self'; "
                + "object-src 'none'; "
                + "base-uri 'self'; "
                + "form-action 'self'; "
                + "frame-ancestors 'self'";
    }

    static String hashes(List<String> sources) {
        StringBuilder b = new StringBuilder();
        for (String s : sources) {
            if (b.length() > 0) {
                b.append(' ');
            }
            b.append("'sha256-").append(sha256(s)).append('\'');
        }
        return b.toString();
    }

    static String sha256(String source) {
        try {
            return Base64.getEncoder().encodeToString(
                    MessageDigest.getInstance("SHA-256").digest(source.getBytes(StandardCharsets.UTF_8)));
        } catch (NoSuchAlgorithmException e) {
            throw new IllegalStateException(e);
        }
    }

    /** True for a content type the browser parses as HTML. */
    static boolean isHtml(String contentType) {
        if (contentType == null) {
            return false;
        }
        String t = contentType.toLowerCase(Locale.ROOT).trim();
        return t.startsWith("text/html") || t.startsWith("application/xhtml+xml");
    }

    /**
     * The response with every {@code <script} tag of an HTML body given the nonce. Whether the
     * body is HTML is decided at its first write; an HTML body's length changes, so a length
     * set for it is dropped (the container then chunks).
     */
    static final class NonceResponse extends HttpServletResponseWrapper {
        private final String nonce;
        private final boolean eval;
        private ScriptNonce.Chars chars;
        private PrintWriter writer;
        private ScriptNonce.Bytes bytes;

        NonceResponse(HttpServletResponse resp, String nonce, boolean eval) {
            super(resp);
            this.nonce = nonce;
            this.eval = eval;
        }

        private boolean html() {
            return isHtml(getContentType());
        }

        @Override
        public PrintWriter getWriter() throws IOException {
            if (writer == null) {
                chars = new ScriptNonce.Chars(super.getWriter(), this::html, nonce);
                writer = new PrintWriter(chars, false);
            }
            return writer;
        }

        @Override
        public ServletOutputStream getOutputStream() throws IOException {
            if (bytes == null) {
                bytes = new ScriptNonce.Bytes(super.getOutputStream(), this::html, nonce);
            }
            return bytes;
        }

        @Override
        public void setContentLength(int len) {
            if (!html()) {
                super.setContentLength(len);
            }
        }

        @Override
        public void setContentLengthLong(long len) {
            if (!html()) {
                super.setContentLengthLong(len);
            }
        }

        @Override
        public void setHeader(String name, String value) {
            if (!(html() && "content-length".equalsIgnoreCase(name))) {
                super.setHeader(name, value);
            }
        }

        @Override
        public void addHeader(String name, String value) {
            if (!(html() && "content-length".equalsIgnoreCase(name))) {
                super.addHeader(name, value);
            }
        }

        @Override
        public void setIntHeader(String name, int value) {
            if (!(html() && "content-length".equalsIgnoreCase(name))) {
                super.setIntHeader(name, value);
            }
        }

        @Override
        public void resetBuffer() {
            super.resetBuffer();
            forget();
        }

        @Override
        public void reset() {
            super.reset();
            // reset() drops every header: the policy goes back on
            setHeaders((HttpServletResponse) getResponse(), nonce, eval);
            forget();
        }

        private void forget() {
            if (chars != null) {
                chars.reset();
            }
            if (bytes != null) {
                bytes.reset();
            }
        }

        /** Writes what the rewriters hold back; called when the request is done. */
        void finish() throws IOException {
            if (writer != null) {
                writer.flush();
                chars.finish();
                writer.flush();
            }
            if (bytes != null) {
                bytes.finish();
            }
        }
    }
}
