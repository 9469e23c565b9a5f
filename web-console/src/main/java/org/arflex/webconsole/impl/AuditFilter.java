package org.arflex.webconsole.impl;

import jakarta.servlet.Filter;
import jakarta.servlet.FilterChain;
import jakarta.servlet.ServletException;
import jakarta.servlet.ServletRequest;
import jakarta.servlet.ServletResponse;
import jakarta.servlet.http.HttpServletRequest;
import jakarta.servlet.http.HttpServletResponse;
import java.io.IOException;
import java.net.URLDecoder;
import java.nio.charset.StandardCharsets;
import java.nio.file.Path;
import java.time.Clock;
import java.util.Base64;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Locale;
import java.util.Map;
import java.util.Set;
import org.osgi.framework.BundleContext;
import org.osgi.service.component.annotations.Activate;
import org.osgi.service.component.annotations.Component;
import org.osgi.service.component.annotations.Deactivate;

/**
 * Writes every state-changing request to the console into the {@link AuditLog}: every method
 * but GET, HEAD, OPTIONS and TRACE whose path reaches the console as {@link CrossSiteFilter}
 * reads it (Felix's own pages and ours, cross-site refusals included). It runs first of the
 * console's filters (highest ranking), after the Web Console's login (the whiteboard calls the
 * context's security check before any filter), so a request it sees has an authenticated
 * user; logins are audited by {@link ConsoleLogin} (issue 30).
 *
 * <p>A request a guard refused before it had any effect (it sets {@link #REFUSED}: the
 * cross-site guard, the CSRF check, the transport filter) is not written one by one but
 * sampled per origin ({@link AuditTrail}), so a page on another site cannot flush the log by
 * making the operator's browser post at the console; an accepted change also goes to the
 * security history ({@value AuditTrail#SECURITY_FILE}), which such refusals cannot rotate.
 *
 * <p>What is recorded of the request: the parameters that say what was asked ({@link #PARAMS})
 * from the query string and from an {@code application/x-www-form-urlencoded} body (never
 * from an upload). Configuration values are not recorded, only their names
 * ({@code propertylist}).
 */
@Component(service = {Filter.class, AuditFilter.class}, property = {
    "osgi.http.whiteboard.filter.pattern=/*",
    "osgi.http.whiteboard.context.select=(osgi.http.whiteboard.context.name=*)",
    "osgi.http.whiteboard.filter.name=arflex-audit",
    "service.ranking:Integer=1000"})
public class AuditFilter implements Filter {
    /** Request attribute: why a request was refused or failed (set by our filters and pages). */
    static final String REASON = "org.arflex.webconsole.audit.reason";
    /** Request attribute: set (to anything) when a guard refused the request before any effect. */
    static final String REFUSED = "org.arflex.webconsole.audit.refused";
    /** Framework or system property naming the runtime's home (else env ARFLEX_HOME). */
    static final String HOME_PROPERTY = "arflex.home";
    /** The parameters recorded, when present. */
    static final List<String> PARAMS = List.of("action", "name", "param", "value", "cmd", "id", "file", "url",
            "sha256", "targets", "apply", "delete", "propertylist", "factoryPid", "shutdown_type", "actions", "plan");
    private static final Set<String> SAFE = Set.of("GET", "HEAD", "OPTIONS", "TRACE");

    private AuditTrail trail;

    /** For SCR. */
    public AuditFilter() {
    }

    /** With the security history beside {@code log}. */
    AuditFilter(AuditLog log) {
        this(new AuditTrail(log, new AuditLog(log.file().resolveSibling(AuditTrail.SECURITY_FILE)), Clock.systemUTC()));
    }

    AuditFilter(AuditTrail trail) {
        this.trail = trail;
    }

    @Activate
    void activate(BundleContext bc) {
        Path home = home(bc);
        this.trail = new AuditTrail(new AuditLog(home.resolve(AuditLog.FILE)),
                new AuditLog(home.resolve(AuditTrail.SECURITY_FILE), AuditTrail.SECURITY_FILE_BYTES, AuditLog.DEFAULT_KEEP,
                        Clock.systemUTC()), Clock.systemUTC());
    }

    @Deactivate
    void deactivate() {
        trail.close();
    }

    AuditLog log() {
        return trail.main();
    }

    AuditTrail trail() {
        return trail;
    }

    /** The runtime's home: {@value #HOME_PROPERTY}, else env ARFLEX_HOME, else the bundle's data area. */
    static Path home(BundleContext bc) {
        String configured = bc.getProperty(HOME_PROPERTY);
        if (configured != null && !configured.isBlank()) {
            return Path.of(configured);
        }
        String env = System.getenv("ARFLEX_HOME");
        if (env != null && !env.isBlank()) {
            return Path.of(env);
        }
        return bc.getDataFile("").toPath();
    }

    @Override
    public void doFilter(ServletRequest request, ServletResponse response, FilterChain chain)
            throws IOException, ServletException {
        if (!(request instanceof HttpServletRequest req) || !(response instanceof HttpServletResponse resp)
                || SAFE.contains(req.getMethod())) {
            chain.doFilter(request, response);
            return;
        }
        ConsolePath.Result where = ConsolePath.of(req, CrossSiteFilter.CONSOLE_ROOT);
        if (!where.guarded()) {
            chain.doFilter(request, response);
            return;
        }
        Throwable failure = null;
        try {
            chain.doFilter(request, response);
        } catch (IOException | ServletException | RuntimeException | Error e) {
            failure = e;
            throw e;
        } finally {
            int status = failure != null ? 500 : resp.getStatus();
            Object why = req.getAttribute(REASON);
            String reason = why != null ? why.toString()
                    : failure != null ? failure.getClass().getSimpleName() + ": " + failure.getMessage() : null;
            if (req.getAttribute(REFUSED) != null) {
                trail.refused(origin(req), user(req), req.getRemoteAddr(), req.getMethod(), path(req, where), params(req),
                        status, reason);
            } else {
                trail.request(user(req), req.getRemoteAddr(), req.getMethod(), path(req, where), params(req), status,
                        reason);
            }
        }
    }

    /** Where a request says it comes from: its Origin, else its Referer's origin, else that it says neither. */
    static String origin(HttpServletRequest req) {
        String o = req.getHeader("Origin");
        if (o == null) {
            String r = req.getHeader("Referer");
            if (r != null) {
                int slash = r.indexOf('/', r.indexOf("//") < 0 ? 0 : r.indexOf("//") + 2);
                o = slash < 0 ? r : r.substring(0, slash);
            }
        }
        if (o == null) {
            return "(no Origin or Referer)";
        }
        return AuditTrail.cut(o, 100);
    }

    /** The authenticated user: the container's, else the Basic login the console accepted. */
    static String user(HttpServletRequest req) {
        String u = req.getRemoteUser();
        if (u != null) {
            return u;
        }
        String auth = req.getHeader("Authorization");
        if (auth != null && auth.regionMatches(true, 0, "Basic ", 0, 6)) {
            try {
                String pair = new String(Base64.getDecoder().decode(auth.substring(6).trim()), StandardCharsets.UTF_8);
                int colon = pair.indexOf(':');
                return colon < 0 ? pair : pair.substring(0, colon);
            } catch (IllegalArgumentException e) {
                return null;
            }
        }
        return null;
    }

    /** The path as the guard reads it; the raw URI (marked) when it cannot be normalised. */
    static String path(HttpServletRequest req, ConsolePath.Result where) {
        String uri = req.getRequestURI();
        if (where.verdict() == ConsolePath.Verdict.UNREADABLE || uri == null) {
            return "(unreadable: " + where.why() + ") " + uri;
        }
        try {
            return ConsolePath.normalise(uri);
        } catch (IllegalArgumentException e) {
            return "(unreadable: " + e.getMessage() + ") " + uri;
        }
    }

    /**
     * The recorded parameters: from the query string, and from a form-urlencoded body (the
     * container bounds its size; a forged form's {@code action} is worth recording). Other
     * bodies (uploads, contracts) are never read here.
     */
    static Map<String, String> params(HttpServletRequest req) {
        Map<String, String> out = new LinkedHashMap<>();
        String q = req.getQueryString();
        if (q != null) {
            for (String pair : q.split("&")) {
                int eq = pair.indexOf('=');
                String k = decode(eq < 0 ? pair : pair.substring(0, eq));
                if (k != null && PARAMS.contains(k) && !out.containsKey(k)) {
                    out.put(k, eq < 0 ? "" : decode(pair.substring(eq + 1)));
                }
            }
        }
        String ct = req.getContentType();
        if (ct != null && ct.toLowerCase(Locale.ROOT).startsWith("application/x-www-form-urlencoded")) {
            for (String k : PARAMS) {
                if (!out.containsKey(k)) {
                    try {
                        String v = req.getParameter(k);
                        if (v != null) {
                            out.put(k, v);
                        }
                    } catch (RuntimeException e) {
                        // a body the servlet consumed itself: what the query string said is all
                        return out;
                    }
                }
            }
        }
        out.values().removeIf(v -> v == null);
        return out;
    }

    private static String decode(String s) {
        try {
            return URLDecoder.decode(s, StandardCharsets.UTF_8);
        } catch (IllegalArgumentException e) {
            return s;
        }
    }
}
