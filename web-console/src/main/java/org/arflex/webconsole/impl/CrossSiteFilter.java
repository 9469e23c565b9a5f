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
        if (request instanceof HttpServletRequest req && response instanceof HttpServletResponse resp
                && !SAFE.contains(req.getMethod()) && req.getRequestURI().startsWith(CONSOLE_ROOT)) {
            String why = Csrf.sameOriginRefusal(req);
            if (why != null) {
                resp.sendError(HttpServletResponse.SC_FORBIDDEN, why);
                return;
            }
        }
        chain.doFilter(request, response);
    }
}
