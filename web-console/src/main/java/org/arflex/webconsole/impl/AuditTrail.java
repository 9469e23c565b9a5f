package org.arflex.webconsole.impl;

import java.time.Clock;
import java.time.Duration;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;

/**
 * Where the console's audit entries go (issue 30): the audit log of every state-changing request
 * ({@code console-audit.log}), and a separate, bounded <em>security history</em>
 * ({@code console-security.log}: logins, accepted changes, refusals) that ordinary traffic does
 * not rotate.
 *
 * <p>Nothing an unauthenticated page or client can send is written one entry per request:
 * requests the guards refused before any effect (cross-site, CSRF token, transport) are sampled
 * per origin ({@link EventSampler}: the first 5 of an origin per minute, 20 in all, with their
 * parameters cut to {@value #SAMPLE_VALUE} characters; the rest counted, one summary line per
 * origin and minute, method {@code REFUSED}); failed logins and logins refused during a back-off
 * are sampled per client the same way (method {@code LOGIN}, status 401 or 429, the user name
 * cut to {@value #USER_CHARS} characters). So a flood writes at most about 60 lines a minute to
 * either file whatever its rate, and the history of changes and logins before it stays.
 */
final class AuditTrail {
    /** The security history's file name under the home folder. */
    static final String SECURITY_FILE = "console-security.log";
    /** Longest parameter value a refused request's sample keeps. */
    static final int SAMPLE_VALUE = 32;
    /** Longest user name a login entry keeps. */
    static final int USER_CHARS = 64;
    static final Duration WINDOW = Duration.ofMinutes(1);

    private final AuditLog main;
    private final AuditLog security;
    private final EventSampler refusals;
    private final EventSampler failedLogins;
    private final EventSampler lockedLogins;

    AuditTrail(AuditLog main, AuditLog security, Clock clock) {
        this.main = main;
        this.security = security;
        this.refusals = new EventSampler(clock, WINDOW, 5, 20, 16);
        this.failedLogins = new EventSampler(clock, WINDOW, 5, 20, 16);
        this.lockedLogins = new EventSampler(clock, WINDOW, 2, 10, 16);
    }

    AuditLog main() {
        return main;
    }

    AuditLog security() {
        return security;
    }

    /** An answered state-changing request: the audit log; an accepted one (below 400) the history too. */
    void request(String user, String remote, String method, String path, Map<String, String> params, int status,
            String reason) {
        summaries();
        main.record(user, remote, method, path, params, status, reason);
        if (status >= 200 && status < 400) {
            security.record(user, remote, method, path, params, status, reason);
        }
    }

    /** A request the guards refused before it had any effect: sampled per origin. */
    void refused(String origin, String user, String remote, String method, String path, Map<String, String> params,
            int status, String reason) {
        summaries();
        if (refusals.admit(origin)) {
            Map<String, String> p = new LinkedHashMap<>();
            params.forEach((k, v) -> p.put(k, cut(v, SAMPLE_VALUE)));
            p.put("origin", origin);
            both(user, remote, method, path, p, status, reason);
        }
    }

    /** A login whose password was checked and found right. */
    void loginSucceeded(String user, String remote, String path) {
        summaries();
        both(cut(user, USER_CHARS), remote, "LOGIN", path, Map.of(), 200, null);
    }

    /** A login whose password was checked and found wrong (or an unknown user): sampled per client. */
    void loginFailed(String user, String remote, String path) {
        summaries();
        if (failedLogins.admit(remote)) {
            both(cut(user, USER_CHARS), remote, "LOGIN", path, Map.of(), 401, "wrong user name or password");
        }
    }

    /** A login refused unchecked because of a back-off: sampled per client. */
    void loginLocked(String user, String remote, String path, LoginLimiter.Lock lock) {
        summaries();
        if (lockedLogins.admit(remote)) {
            both(cut(user, USER_CHARS), remote, "LOGIN", path, Map.of(), 429, "back-off after " + lock.failures()
                    + " failed logins (" + lock.scope() + "): refused unchecked for " + lock.retryAfterSeconds() + " s");
        }
    }

    /** Per origin, the refusals of the current minute counted and not written (yet). */
    Map<String, Long> refusalsNotWritten() {
        summaries();
        return refusals.pending();
    }

    /** Writes what is still counted (the console stops). */
    void close() {
        write(refusals.drain(), "REFUSED", 403, "refused requests");
        write(failedLogins.drain(), "LOGIN", 401, "failed logins");
        write(lockedLogins.drain(), "LOGIN", 429, "logins refused during a back-off");
    }

    /** The summaries of minutes that are over, before anything else is written. */
    private void summaries() {
        write(refusals.due(), "REFUSED", 403, "refused requests");
        write(failedLogins.due(), "LOGIN", 401, "failed logins");
        write(lockedLogins.due(), "LOGIN", 429, "logins refused during a back-off");
    }

    private void write(List<EventSampler.Summary> due, String method, int status, String what) {
        for (EventSampler.Summary s : due) {
            Map<String, String> p = new LinkedHashMap<>();
            p.put("key", s.key());
            p.put("count", Long.toString(s.notWritten()));
            p.put("seen", Long.toString(s.seen()));
            p.put("from", s.from().toString());
            p.put("to", s.to().toString());
            both(null, null, method, "(summary)", p, status, s.notWritten() + " more " + what + " from " + s.key()
                    + " between " + s.from() + " and " + s.to() + ", counted and not written one by one");
        }
    }

    private void both(String user, String remote, String method, String path, Map<String, String> params, int status,
            String reason) {
        main.record(user, remote, method, path, params, status, reason);
        security.record(user, remote, method, path, params, status, reason);
    }

    /** At most {@code n} characters, control characters replaced (a user name is whatever a client sent). */
    static String cut(String s, int n) {
        if (s == null) {
            return null;
        }
        String t = s.length() <= n ? s : s.substring(0, n) + "…(" + s.length() + " chars)";
        return t.replaceAll("\\p{Cntrl}", "?");
    }
}
