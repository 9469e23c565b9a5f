package org.arflex.webconsole.impl;

import jakarta.servlet.Filter;
import jakarta.servlet.FilterChain;
import jakarta.servlet.ServletException;
import jakarta.servlet.ServletRequest;
import jakarta.servlet.ServletResponse;
import jakarta.servlet.http.HttpServletRequest;
import jakarta.servlet.http.HttpServletResponse;
import java.io.IOException;
import java.util.Set;
import org.osgi.service.component.annotations.Component;

/**
 * Guards the Felix Web Console's own pages (bundles, configuration, ...) against cross-site
 * requests: every non-safe method under the console root must come from the console's own
 * origin. Our pages additionally require the per-session token ({@link Csrf}).
 *
 * <p>Mapped to every path of every context ({@code /*}): whether a request is the console's is
 * decided inside, on the path as routed and normalised ({@link ConsolePath}), never on the raw
 * request URI, which a client can spell so that it does not look like the console's while
 * the container still routes it there (issue 16).
 */
@Component(service = Filter.class, property = {
    "osgi.http.whiteboard.filter.pattern=/*",
    "osgi.http.whiteboard.context.select=(osgi.http.whiteboard.context.name=*)",
    "osgi.http.whiteboard.filter.name=arflex-cross-site-guard"})
public class CrossSiteFilter implements Filter {
    /** The console root (felix.webconsole.manager.root of the runtime). */
    static final String CONSOLE_ROOT = "/system/console";
    private static final Set<String> SAFE = Set.of("GET", "HEAD", "OPTIONS", "TRACE");

    @Override
    public void doFilter(ServletRequest request, ServletResponse response, FilterChain chain)
            throws IOException, ServletException {
        if (request instanceof HttpServletRequest req && response instanceof HttpServletResponse resp) {
            String why = refusal(req);
            if (why != null) {
                req.setAttribute(AuditFilter.REASON, why);
                req.setAttribute(AuditFilter.REFUSED, Boolean.TRUE);
                resp.sendError(HttpServletResponse.SC_FORBIDDEN, why);
                return;
            }
        }
        chain.doFilter(request, response);
    }

    /**
     * Null when {@code req} may go on, otherwise why not. Safe methods always go on; any other
     * method (whatever its case or name) must be same-origin when any view of its path reaches
     * the console, or when its path cannot be read unambiguously (fail closed).
     */
    static String refusal(HttpServletRequest req) {
        if (SAFE.contains(req.getMethod())) {
            return null;
        }
        ConsolePath.Result where = ConsolePath.of(req, CONSOLE_ROOT);
        if (!where.guarded()) {
            return null;
        }
        String why = Csrf.sameOriginRefusal(req);
        if (why == null) {
            return null;
        }
        return where.verdict() == ConsolePath.Verdict.UNREADABLE
                ? "request path cannot be normalised (" + where.why() + "), so it is treated as the console's: " + why
                : why;
    }
}
