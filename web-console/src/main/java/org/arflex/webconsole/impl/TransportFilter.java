package org.arflex.webconsole.impl;

import jakarta.servlet.Filter;
import jakarta.servlet.FilterChain;
import jakarta.servlet.ServletException;
import jakarta.servlet.ServletRequest;
import jakarta.servlet.ServletResponse;
import jakarta.servlet.http.HttpServletRequest;
import jakarta.servlet.http.HttpServletResponse;
import java.io.IOException;
import java.net.InetAddress;
import java.net.UnknownHostException;
import org.osgi.service.component.annotations.Component;

/**
 * Remote use only over TLS (issue 16, docs/DECISIONS.md D16): the console's Basic credentials
 * and session token must never cross a network in clear. {@code scripts/run-cell.sh} binds the
 * console to loopback, or, with {@code ARFLEX_CONSOLE_HOST} beyond loopback, serves HTTPS only;
 * this filter is the second line, whatever the configuration says: a request that did not come
 * over TLS and arrived on an address that is not a loopback address is refused (421) before any
 * page or login sees it.
 */
@Component(service = Filter.class, property = {
    "osgi.http.whiteboard.filter.pattern=/*",
    "osgi.http.whiteboard.context.select=(osgi.http.whiteboard.context.name=*)",
    "osgi.http.whiteboard.filter.name=arflex-transport",
    "service.ranking:Integer=1100"})
public class TransportFilter implements Filter {

    @Override
    public void doFilter(ServletRequest request, ServletResponse response, FilterChain chain)
            throws IOException, ServletException {
        if (request instanceof HttpServletRequest req && response instanceof HttpServletResponse resp) {
            String why = refusal(req.isSecure(), req.getLocalAddr());
            if (why != null) {
                req.setAttribute(AuditFilter.REASON, why);
                req.setAttribute(AuditFilter.REFUSED, Boolean.TRUE);
                resp.sendError(421, why);
                return;
            }
        }
        chain.doFilter(request, response);
    }

    /** Null when a request may go on; else why not. */
    static String refusal(boolean secure, String localAddr) {
        if (secure || loopback(localAddr)) {
            return null;
        }
        return "the console answers plain HTTP on loopback only; from " + localAddr
                + " use HTTPS (ARFLEX_CONSOLE_HOST, scripts/console-tls.sh)";
    }

    private static boolean loopback(String addr) {
        if (addr == null || addr.isEmpty()) {
            return false;
        }
        try {
            // a literal address only: never resolve a name here
            if (!addr.matches("[0-9a-fA-F.:%\\[\\]]+")) {
                return false;
            }
            return InetAddress.getByName(addr.replace("[", "").replace("]", "")).isLoopbackAddress();
        } catch (UnknownHostException e) {
            return false;
        }
    }
}
