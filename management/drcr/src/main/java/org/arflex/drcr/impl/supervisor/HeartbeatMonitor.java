package org.arflex.drcr.impl.supervisor;

import java.util.Map;
import java.util.concurrent.ConcurrentHashMap;
import java.util.function.BiConsumer;

/**
 * Writes the runtime heartbeat into every watched control block and reports an RT half whose
 * own heartbeat went stale (a hang) once. {@link #check(long)} is called periodically by the
 * runtime's heartbeat thread (or by a test with a simulated time); it never blocks.
 */
public final class HeartbeatMonitor {

    private record Watch(String name, RtHalf half, long timeoutNs, long sinceNs) {
    }

    private final Map<RtHalf, Watch> watched = new ConcurrentHashMap<>();
    private final Map<RtHalf, Boolean> reported = new ConcurrentHashMap<>();
    private final BiConsumer<RtHalf, String> onHang;

    /**
     * @param onHang called (on the checking thread) with the half and the reason, once per half
     */
    public HeartbeatMonitor(BiConsumer<RtHalf, String> onHang) {
        this.onHang = onHang;
    }

    /** Starts watching a running half; {@code nowNs} is when it was started. */
    public void watch(String name, RtHalf half, long timeoutMs, long nowNs) {
        watched.put(half, new Watch(name, half, timeoutMs * 1_000_000L, nowNs));
    }

    /** Stops watching (before an orderly stop, or after an exit). */
    public void unwatch(RtHalf half) {
        watched.remove(half);
        reported.remove(half);
    }

    /** Number of halves watched. */
    public int size() {
        return watched.size();
    }

    /** One round: runtime heartbeat out, RT heartbeat in. */
    public void check(long nowNs) {
        for (Watch w : watched.values()) {
            w.half().runtimeHeartbeat(nowNs);
            long rt = w.half().rtHeartbeatNs();
            long last = rt != 0 ? rt : w.sinceNs();
            long age = nowNs - last;
            if (w.timeoutNs() > 0 && age > w.timeoutNs() && reported.putIfAbsent(w.half(), Boolean.TRUE) == null) {
                onHang.accept(w.half(), "hung: no RT heartbeat for " + age / 1_000_000L + " ms (timeout "
                        + w.timeoutNs() / 1_000_000L + " ms)");
            }
        }
    }
}
