package org.arflex.webconsole.impl;

import jakarta.servlet.http.HttpServletRequest;
import jakarta.servlet.http.HttpServletResponse;
import jakarta.servlet.http.HttpSession;
import java.io.IOException;
import java.nio.charset.StandardCharsets;
import java.security.GeneralSecurityException;
import java.security.MessageDigest;
import java.security.SecureRandom;
import java.time.Clock;
import java.util.Base64;
import javax.crypto.Mac;
import javax.crypto.spec.SecretKeySpec;
import org.apache.felix.webconsole.spi.SecurityProvider;
import org.osgi.framework.BundleContext;
import org.osgi.service.component.annotations.Activate;
import org.osgi.service.component.annotations.Component;
import org.osgi.service.component.annotations.Reference;

/**
 * The console's login (issue 30): HTTP Basic, checked here against a salted slow hash
 * ({@link PasswordHash}, framework properties {@value #USER_PROPERTY} and
 * {@value #PASSWORD_PROPERTY}, written by {@code scripts/console-login.sh}), limited per client
 * and over all clients with back-off ({@link LoginLimiter}: 429 with {@code Retry-After}, the
 * password not checked), and audited ({@link AuditTrail}: logins checked by the slow hash,
 * failed and refused ones sampled per client).
 *
 * <p>It is the Web Console's security provider with the id {@value #ID}; {@code run-cell.sh}
 * sets {@code felix.webconsole.security.providers=arflex}, so the Web Console serves nothing
 * until this provider is registered and its own user/password check never accepts anyone (Felix
 * refuses its built-in login while required providers are configured).
 *
 * <p>Basic sends the credentials with every request: the slow hash runs once per credential,
 * and a credential it accepted is then recognised by an HMAC under a key made at start (the
 * password itself is never kept). That recognition is subject to the back-off like any other
 * check, except in a session that already logged in (the console's pages make one), so a
 * guesser on the same address cannot lock out a browser that is logged in.
 */
@Component(service = SecurityProvider.class, property = {
    SecurityProvider.PROPERTY_ID + "=" + ConsoleLogin.ID,
    "service.ranking:Integer=1000"})
public class ConsoleLogin implements SecurityProvider {
    /** The provider id run-cell.sh requires (felix.webconsole.security.providers). */
    static final String ID = "arflex";
    static final String USER_PROPERTY = "arflex.console.username";
    static final String PASSWORD_PROPERTY = "arflex.console.password";
    static final String REALM = "ARFLEX console";
    private static final String SESSION_ATTR = "org.arflex.webconsole.login";
    private static final String REMOTE_USER = "org.osgi.service.http.authentication.remote.user";
    private static final String AUTH_TYPE = "org.osgi.service.http.authentication.type";

    @Reference
    private AuditFilter audit;

    private String user;
    private PasswordHash hash;
    private String problem;
    private LoginLimiter limiter;
    private AuditTrail trail;
    private final Object slow = new Object();
    private final byte[] key = new byte[32];
    private volatile byte[] verified;

    /** For SCR. */
    public ConsoleLogin() {
    }

    ConsoleLogin(String user, String stored, LoginLimiter limiter, AuditTrail trail) {
        configure(user, stored, "test", limiter, trail);
    }

    @Activate
    void activate(BundleContext bc) {
        String stored = bc.getProperty(PASSWORD_PROPERTY);
        String where = "framework property " + PASSWORD_PROPERTY;
        if (stored == null && bc.getProperty("felix.webconsole.password") != null) {
            stored = bc.getProperty("felix.webconsole.password");
            where = "framework property felix.webconsole.password (an old console.properties)";
        }
        configure(bc.getProperty(USER_PROPERTY), stored, where, new LoginLimiter(Clock.systemUTC()), audit.trail());
        if (problem != null) {
            System.err.println("arflex console: every login is refused: " + problem);
        }
    }

    private void configure(String user, String stored, String where, LoginLimiter limiter, AuditTrail trail) {
        this.limiter = limiter;
        this.trail = trail;
        new SecureRandom().nextBytes(key);
        if (user == null || user.isBlank()) {
            problem = "no console user is configured (" + USER_PROPERTY + "); run scripts/console-login.sh";
            return;
        }
        try {
            this.hash = PasswordHash.parse(stored, where);
            this.user = user;
        } catch (IllegalArgumentException e) {
            problem = e.getMessage();
        }
    }

    @Override
    public Object authenticate(HttpServletRequest req, HttpServletResponse resp) {
        try {
            return login(req, resp);
        } catch (IOException e) {
            return null;
        }
    }

    private String login(HttpServletRequest req, HttpServletResponse resp) throws IOException {
        if (problem != null) {
            answer(resp, 503, "the console login is not configured: " + problem);
            return null;
        }
        String[] cred = basic(req.getHeader("Authorization"));
        if (cred == null) {
            challenge(resp);
            return null;
        }
        String client = req.getRemoteAddr();
        byte[] tag = tag(cred);
        HttpSession session = session(req);
        if (session != null && session.getAttribute(SESSION_ATTR) instanceof byte[] known
                && MessageDigest.isEqual(known, tag)) {
            return accepted(req, cred[0]);
        }
        LoginLimiter.Lock lock = limiter.check(client);
        if (lock == null) {
            byte[] before = verified;
            if (before == null || !MessageDigest.isEqual(before, tag)) {
                Checked c = slowCheck(cred, tag, client, req.getRequestURI());
                lock = c.lock();
                if (lock == null && !c.right()) {
                    trail.loginFailed(cred[0], client, req.getRequestURI());
                    challenge(resp);
                    return null;
                }
            }
        }
        if (lock != null) {
            trail.loginLocked(cred[0], client, req.getRequestURI(), lock);
            resp.setHeader("Retry-After", Long.toString(lock.retryAfterSeconds()));
            answer(resp, 429, "too many failed logins (" + lock.scope() + "): try again in " + lock.retryAfterSeconds()
                    + " s");
            return null;
        }
        limiter.succeeded(client);
        if (session != null) {
            session.setAttribute(SESSION_ATTR, tag);
        }
        return accepted(req, cred[0]);
    }

    /**
     * The slow hash, one at a time. Guesses sent side by side wait here, and each asks the
     * limiter again once it is its turn: by then the failures before it are counted, so a
     * parallel burst gets no more checks than a sequential one. A wrong one is counted; a right
     * one becomes {@link #verified}.
     */
    private Checked slowCheck(String[] cred, byte[] tag, String client, String path) {
        synchronized (slow) {
            LoginLimiter.Lock lock = limiter.check(client);
            if (lock != null) {
                return new Checked(lock, false);
            }
            byte[] meanwhile = verified;
            if (meanwhile != null && MessageDigest.isEqual(meanwhile, tag)) {
                return new Checked(null, true); // the same login, checked while this one waited
            }
            // the slow hash runs even for a wrong user name, so timing does not tell names apart
            boolean rightUser = MessageDigest.isEqual(user.getBytes(StandardCharsets.UTF_8),
                    cred[0].getBytes(StandardCharsets.UTF_8));
            boolean right = hash.matches(cred[1]) && rightUser;
            if (right) {
                verified = tag;
                trail.loginSucceeded(cred[0], client, path);
            } else {
                limiter.failed(client);
            }
            return new Checked(null, right);
        }
    }

    /** What the slow check said: refused unchecked ({@code lock}), or checked and right or not. */
    private record Checked(LoginLimiter.Lock lock, boolean right) {
    }

    private static String accepted(HttpServletRequest req, String name) {
        req.setAttribute(AUTH_TYPE, HttpServletRequest.BASIC_AUTH);
        req.setAttribute(REMOTE_USER, name);
        return name;
    }

    @Override
    public boolean authorize(Object user, String role) {
        return user != null;
    }

    @Override
    public void logout(HttpServletRequest req, HttpServletResponse resp) {
        HttpSession s = session(req);
        if (s != null) {
            s.removeAttribute(SESSION_ATTR);
        }
    }

    /** User and password of a Basic header; null when there is none or it cannot be read. */
    static String[] basic(String header) {
        if (header == null || !header.regionMatches(true, 0, "Basic ", 0, 6)) {
            return null;
        }
        String pair;
        try {
            pair = new String(Base64.getDecoder().decode(header.substring(6).trim()), StandardCharsets.UTF_8);
        } catch (IllegalArgumentException e) {
            return null;
        }
        int colon = pair.indexOf(':');
        return colon < 0 ? new String[] {pair, ""} : new String[] {pair.substring(0, colon), pair.substring(colon + 1)};
    }

    private byte[] tag(String[] cred) {
        try {
            Mac mac = Mac.getInstance("HmacSHA256");
            mac.init(new SecretKeySpec(key, "HmacSHA256"));
            mac.update(cred[0].getBytes(StandardCharsets.UTF_8));
            mac.update((byte) 0);
            return mac.doFinal(cred[1].getBytes(StandardCharsets.UTF_8));
        } catch (GeneralSecurityException e) {
            throw new IllegalStateException("HmacSHA256 is not available in this JDK", e);
        }
    }

    private static HttpSession session(HttpServletRequest req) {
        try {
            return req.getSession(false);
        } catch (RuntimeException e) {
            return null;
        }
    }

    private static void challenge(HttpServletResponse resp) throws IOException {
        resp.setHeader("WWW-Authenticate", "Basic realm=\"" + REALM + "\", charset=\"UTF-8\"");
        answer(resp, 401, "");
    }

    private static void answer(HttpServletResponse resp, int status, String text) throws IOException {
        byte[] b = text.getBytes(StandardCharsets.UTF_8);
        resp.setStatus(status);
        resp.setContentType("text/plain;charset=UTF-8");
        resp.setContentLength(b.length);
        if (b.length > 0) {
            resp.getOutputStream().write(b);
        }
        resp.flushBuffer();
    }
}
