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
 * per origin ({@link EventSampler}: the first 5 of an origin per minute, 10 over all origins,
 * with their parameters cut to {@value #SAMPLE_VALUE} characters; the rest counted, and summed
 * up in one line per minute, method {@code REFUSED}, with each origin's count); failed logins
 * (5 per client, 10 in all) and logins refused during a back-off (2 per client, 5 in all) are
 * sampled per client the same way (method {@code LOGIN}, status 401 or 429, the user name cut to
 * {@value #USER_CHARS} characters). So floods of every kind together write at most 28 lines a
 * minute to either file whatever their rate; the security history's files are larger
 * ({@value #SECURITY_FILE_BYTES} bytes, 3 kept), so the changes and logins before a flood stay
 * for hours of it (docs/decisions/D81 has the figures).
 */
final class AuditTrail {
    /** The security history's file name under the home folder. */
    static final String SECURITY_FILE = "console-security.log";
    /** Longest parameter value a refused request's sample keeps. */
    static final int SAMPLE_VALUE = 32;
    /** Longest user name a login entry keeps. */
    static final int USER_CHARS = 64;
    static final Duration WINDOW = Duration.ofMinutes(1);
    /** Size of one file of the security history before it is rotated (3 rotated files kept). */
    static final long SECURITY_FILE_BYTES = 4L << 20;

    private final AuditLog main;
    private final AuditLog security;
    private final EventSampler refusals;
    private final EventSampler failedLogins;
    private final EventSampler lockedLogins;

    AuditTrail(AuditLog main, AuditLog security, Clock clock) {
        this.main = main;
        this.security = security;
        this.refusals = new EventSampler(clock, WINDOW, 5, 10, 16);
        this.failedLogins = new EventSampler(clock, WINDOW, 5, 10, 16);
        this.lockedLogins = new EventSampler(clock, WINDOW, 2, 5, 16);
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

    /** One line for a minute's counts of one kind: the total, then each key's (at most 17 keys). */
    private void write(List<EventSampler.Summary> due, String method, int status, String what) {
        if (due.isEmpty()) {
            return;
        }
        long notWritten = due.stream().mapToLong(EventSampler.Summary::notWritten).sum();
        Map<String, String> p = new LinkedHashMap<>();
        p.put("count", Long.toString(notWritten));
        p.put("seen", Long.toString(due.stream().mapToLong(EventSampler.Summary::seen).sum()));
        p.put("from", due.get(0).from().toString());
        p.put("to", due.get(0).to().toString());
        StringBuilder who = new StringBuilder();
        for (EventSampler.Summary s : due) {
            p.putIfAbsent(s.key(), Long.toString(s.notWritten()));
            who.append(who.length() == 0 ? "" : ", ").append(s.key()).append(' ').append(s.notWritten());
        }
        both(null, null, method, "(summary)", p, status, notWritten + " more " + what + " between " + p.get("from")
                + " and " + p.get("to") + ", counted and not written one by one: " + who);
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
