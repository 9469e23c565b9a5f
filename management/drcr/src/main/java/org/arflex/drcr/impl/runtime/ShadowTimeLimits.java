package org.arflex.drcr.impl.runtime;

import java.util.Locale;

/**
 * The time rules of a shadow run (D42), on the actor's clock
 * ({@link org.arflex.drcr.impl.lifecycle.Clock#millis()}), which its looks follow: the new half
 * must not go without a cycle for its heartbeat timeout, and must run its cycles within four
 * times their periods plus a second (a half that does not cycle).
 */
final class ShadowTimeLimits {
    private final long shadow;
    private final long heartbeatMs;
    private final long limitMs;
    private final long tEndMs;
    private long lastProgressMs;

    ShadowTimeLimits(Instance next, long shadow, long nowMs) {
        this.shadow = shadow;
        this.heartbeatMs = next.contract.fault().heartbeatTimeoutMs();
        long period = Math.max(1, next.contract.timing().periodNs());
        this.limitMs = (4 * shadow * period + 1_000_000_000L) / 1_000_000L;
        this.lastProgressMs = nowMs;
        this.tEndMs = nowMs + limitMs;
    }

    /** The new half ran a cycle since the last look. */
    void progressed(long nowMs) {
        lastProgressMs = nowMs;
    }

    /** Why the new half, short of its cycles, went silent for too long, or null. */
    String silent(long nowMs, long cycles) {
        long silentMs = nowMs - lastProgressMs;
        if (cycles < shadow && silentMs >= heartbeatMs) {
            return "it ran no cycle for " + silentMs + " ms (heartbeat timeout " + heartbeatMs + " ms)";
        }
        return null;
    }

    /** Why the new half's time for its cycles is over, or null. */
    String overdue(long nowMs, long cycles) {
        if (nowMs - tEndMs >= 0) {
            return String.format(Locale.ROOT, "it ran only %d of its %d shadow cycles in %d ms", cycles, shadow, limitMs);
        }
        return null;
    }
}
