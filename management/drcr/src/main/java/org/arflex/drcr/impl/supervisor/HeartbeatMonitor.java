package org.arflex.drcr.impl.supervisor;

import java.util.Map;
import java.util.concurrent.ConcurrentHashMap;
import java.util.function.BiConsumer;
import java.util.function.Supplier;

/**
 * Writes the runtime heartbeat into every watched control block and reports an RT half whose
 * own heartbeat went silent (a hang) once. {@link #check(long)} is called every
 * {@link #PERIOD_MS} by the runtime's heartbeat thread (or by a test with a simulated time); it
 * never blocks.
 *
 * <p>Silence is judged in windows, not as the age of the last heartbeat (SAFETY.md 6, issue 15
 * finding 6): each check adds at most two periods to a half's silence, so a stall of the JVM or
 * of the machine that delays the checks themselves is not counted; and while every watched half
 * is silent at once (two or more), that is the machine, not a component: none is reported
 * before its silence reaches {@link #ALL_SILENT_FACTOR} times its timeout. A single half that
 * stops while the others go on is still reported when its silence passes its timeout.
 *
 * <p>Each check also asks a half's {@code damage} probe (its output segments' headers, issue 15
 * finding 5): a segment overwritten or truncated while it runs is reported as that half's fault
 * within one period, so that its restart recreates the segment (consumers hold meanwhile: they
 * judge the header too).
 */
public final class HeartbeatMonitor {

    /** The period of {@link #check(long)} calls. */
    public static final long PERIOD_MS = 20;
    /** While every half is silent, a hang is reported only after this many timeouts. */
    static final int ALL_SILENT_FACTOR = 5;

    private static final class Watch {
        final String name;
        final RtHalf half;
        final long timeoutNs;
        final Supplier<String> damage;
        long lastHb;
        long silenceNs;

        Watch(String name, RtHalf half, long timeoutNs, Supplier<String> damage) {
            this.name = name;
            this.half = half;
            this.timeoutNs = timeoutNs;
            this.damage = damage;
        }
    }

    private final Map<RtHalf, Watch> watched = new ConcurrentHashMap<>();
    private final Map<RtHalf, Boolean> reported = new ConcurrentHashMap<>();
    private final BiConsumer<RtHalf, String> onHang;
    private final long periodNs;
    private long lastCheckNs;

    /**
     * @param onHang called (on the checking thread) with the half and the reason (a hang or a
     *               damaged output), once per half
     */
    public HeartbeatMonitor(BiConsumer<RtHalf, String> onHang) {
        this(onHang, PERIOD_MS);
    }

    HeartbeatMonitor(BiConsumer<RtHalf, String> onHang, long periodMs) {
        this.onHang = onHang;
        this.periodNs = periodMs * 1_000_000L;
    }

    /** Starts watching a running half; {@code nowNs} is when it was started. */
    public void watch(String name, RtHalf half, long timeoutMs, long nowNs) {
        watch(name, half, timeoutMs, nowNs, () -> null);
    }

    /** As {@link #watch(String, RtHalf, long, long)}, with a probe saying which output is damaged (or null). */
    public void watch(String name, RtHalf half, long timeoutMs, long nowNs, Supplier<String> damage) {
        watched.put(half, new Watch(name, half, timeoutMs * 1_000_000L, damage));
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
    public synchronized void check(long nowNs) {
        long step = lastCheckNs == 0 ? 0 : Math.max(0, Math.min(nowNs - lastCheckNs, 2 * periodNs));
        lastCheckNs = nowNs;
        int silent = 0;
        for (Watch w : watched.values()) {
            w.half.runtimeHeartbeat(nowNs);
            long rt = w.half.rtHeartbeatNs();
            if (rt != w.lastHb) {
                w.lastHb = rt;
                w.silenceNs = 0;
            } else {
                w.silenceNs += step;
                silent++;
            }
        }
        boolean machine = silent >= 2 && silent == watched.size();
        for (Watch w : watched.values()) {
            String d = w.damage.get();
            if (d != null && reported.putIfAbsent(w.half, Boolean.TRUE) == null) {
                onHang.accept(w.half, d);
                continue;
            }
            long limit = machine ? ALL_SILENT_FACTOR * w.timeoutNs : w.timeoutNs;
            if (w.timeoutNs > 0 && w.silenceNs > limit && reported.putIfAbsent(w.half, Boolean.TRUE) == null) {
                onHang.accept(w.half, "hung: no RT heartbeat for " + w.silenceNs / 1_000_000L + " ms of supervision (timeout "
                        + w.timeoutNs / 1_000_000L + " ms" + (machine ? ", every half silent" : "") + ")");
            }
        }
    }
}
