package org.arflex.webconsole.impl;

import java.time.Clock;
import java.time.Duration;
import java.time.Instant;
import java.util.LinkedHashMap;
import java.util.Map;

/**
 * Slows password guessing at the console's login, per client address and over all clients:
 * each keeps a count of failed logins; past {@code free} of them every further failure locks
 * it for a back-off that doubles (1 s, 2 s, 4 s, ... up to {@code max}). While the client or
 * the whole console is locked a login is refused without checking the password at all (so a
 * lock also bounds the CPU the slow hash costs); an attempt refused so does not lengthen the
 * lock. A successful login clears its client's count; the global count decays: a failure older
 * than {@code max} no longer counts. The clock is injected (tests never sleep).
 *
 * <p>The table of clients is bounded ({@value #MAX_CLIENTS}): when it is full, clients with no
 * lock left are forgotten first; if all of them are locked, new clients share one entry (fail
 * closed: a flood of addresses cannot buy unlimited guesses).
 */
final class LoginLimiter {
    static final int MAX_CLIENTS = 1024;
    private static final String OVERFLOW = "(other clients)";

    /** Why a login may not be tried now: who is locked, for how long, after how many failures. */
    record Lock(String scope, Duration retryAfter, int failures) {
        long retryAfterSeconds() {
            return Math.max(1, (retryAfter.toMillis() + 999) / 1000);
        }
    }

    private static final class Counter {
        int failures;
        Instant lockedUntil = Instant.MIN;
        Instant lastFailure = Instant.MIN;
    }

    private final Clock clock;
    private final int freePerClient;
    private final int freeGlobal;
    private final Duration base;
    private final Duration max;
    private final Map<String, Counter> clients = new LinkedHashMap<>();
    private final Counter global = new Counter();

    /** The console's: 5 free failures per client, 20 over all, back-off from 1 s to 5 min. */
    LoginLimiter(Clock clock) {
        this(clock, 5, 20, Duration.ofSeconds(1), Duration.ofMinutes(5));
    }

    LoginLimiter(Clock clock, int freePerClient, int freeGlobal, Duration base, Duration max) {
        this.clock = clock;
        this.freePerClient = freePerClient;
        this.freeGlobal = freeGlobal;
        this.base = base;
        this.max = max;
    }

    /** Null when {@code client} may try a login now; else the lock that holds it. */
    synchronized Lock check(String client) {
        Instant now = clock.instant();
        decay(now);
        Counter c = clients.get(key(client));
        if (c != null && now.isBefore(c.lockedUntil)) {
            return new Lock("client " + client, Duration.between(now, c.lockedUntil), c.failures);
        }
        if (now.isBefore(global.lockedUntil)) {
            return new Lock("the console (all clients)", Duration.between(now, global.lockedUntil), global.failures);
        }
        return null;
    }

    /** A failed login of {@code client}: counted, and a lock when past the free ones. */
    synchronized void failed(String client) {
        Instant now = clock.instant();
        decay(now);
        String k = key(client);
        Counter c = clients.computeIfAbsent(k, x -> new Counter());
        count(c, freePerClient, now);
        count(global, freeGlobal, now);
    }

    /** A successful login of {@code client}: its count is cleared (the global one decays). */
    synchronized void succeeded(String client) {
        clients.remove(client);
    }

    private void count(Counter c, int free, Instant now) {
        c.failures++;
        c.lastFailure = now;
        if (c.failures > free) {
            int doublings = Math.min(30, c.failures - free - 1);
            Duration d = base.multipliedBy(1L << doublings);
            c.lockedUntil = now.plus(d.compareTo(max) > 0 ? max : d);
        }
    }

    /** Counts whose last failure is older than the longest back-off are forgotten. */
    private void decay(Instant now) {
        if (!global.lastFailure.equals(Instant.MIN) && global.lastFailure.plus(max).isBefore(now)
                && !now.isBefore(global.lockedUntil)) {
            global.failures = 0;
        }
        clients.values().removeIf(c -> c.lastFailure.plus(max).isBefore(now) && !now.isBefore(c.lockedUntil));
    }

    /** The entry a client is counted in: its own, or the shared one when the table is full of locks. */
    private String key(String client) {
        String k = client == null ? "(unknown)" : client;
        if (clients.containsKey(k) || clients.size() < MAX_CLIENTS) {
            return k;
        }
        Instant now = clock.instant();
        clients.values().removeIf(c -> !now.isBefore(c.lockedUntil));
        return clients.size() < MAX_CLIENTS ? k : OVERFLOW;
    }
}
