package org.arflex.drcr.impl.supervisor;

import java.util.ArrayDeque;
import java.util.Deque;
import org.arflex.contract.FaultPolicy;
import org.arflex.drcr.impl.lifecycle.Clock;

/**
 * The restart decision of one instance, in the style of an Erlang/OTP supervisor child spec and
 * systemd's StartLimitIntervalSec/StartLimitBurst: at most {@code intensity} restarts within
 * {@code windowMs}; the n-th restart inside the window waits {@code backoffMs * 2^(n-1)} (capped
 * at {@link #MAX_BACKOFF_MS}); one more exit inside the window gives up.
 *
 * <p>Not thread-safe: used on the actor thread only.
 */
public final class RestartPolicy {

    /** Upper bound of one backoff delay. */
    public static final long MAX_BACKOFF_MS = 30_000;

    /** What to do after an exit. */
    public record Decision(boolean restart, long delayMs, String reason) {
    }

    private final FaultPolicy policy;
    private final Clock clock;
    private final Deque<Long> recent = new ArrayDeque<>();
    private int total;

    public RestartPolicy(FaultPolicy policy, Clock clock) {
        this.policy = policy;
        this.clock = clock;
    }

    /**
     * Decides about an exit of the RT half.
     *
     * @param abnormal true for a crash, a hang, a signal or a non-zero exit status
     * @param why      what happened, for the reason text
     */
    public Decision onExit(boolean abnormal, String why) {
        switch (policy.restart()) {
            case TEMPORARY:
                return new Decision(false, 0, "not restarted (restart=temporary): " + why);
            case TRANSIENT:
                if (!abnormal) {
                    return new Decision(false, 0, "not restarted after a normal exit (restart=transient): " + why);
                }
                break;
            case PERMANENT:
            default:
                break;
        }
        long now = clock.millis();
        prune(now);
        if (recent.size() >= policy.intensity()) {
            return new Decision(false, 0, "restart intensity exceeded: " + recent.size() + " restarts within "
                    + policy.windowMs() + " ms (intensity " + policy.intensity() + "); last exit: " + why);
        }
        recent.addLast(now);
        total++;
        long delay = policy.backoffMs();
        for (int i = 1; i < recent.size() && delay < MAX_BACKOFF_MS; i++) {
            delay *= 2;
        }
        delay = Math.min(delay, MAX_BACKOFF_MS);
        return new Decision(true, delay, "restart " + recent.size() + "/" + policy.intensity() + " in "
                + delay + " ms after: " + why);
    }

    /** Restarts left in the current window. */
    public int restartsLeft() {
        if (policy.restart() == FaultPolicy.Restart.TEMPORARY) {
            return 0;
        }
        prune(clock.millis());
        return Math.max(0, policy.intensity() - recent.size());
    }

    /** Restarts since install. */
    public int total() {
        return total;
    }

    /** Forgets the history (operator reset of a Failed instance). */
    public void reset() {
        recent.clear();
    }

    private void prune(long now) {
        while (!recent.isEmpty() && now - recent.peekFirst() >= policy.windowMs()) {
            recent.removeFirst();
        }
    }
}
