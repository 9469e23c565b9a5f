package org.arflex.drcr.impl.supervisor;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.lang.reflect.Proxy;
import java.util.ArrayList;
import java.util.HashMap;
import java.util.List;
import java.util.Map;
import org.junit.jupiter.api.Test;

/** Issue 15 finding 6: a stall of the machine is not a hang; one component's hang still is. */
class HeartbeatMonitorTest {

    private final Map<RtHalf, long[]> hb = new HashMap<>();
    private final List<String> hung = new ArrayList<>();
    private final Map<RtHalf, String> names = new HashMap<>();
    private final HeartbeatMonitor m = new HeartbeatMonitor((h, why) -> hung.add(names.get(h) + ": " + why), 20);
    private long now = 1_000_000_000L;

    private RtHalf half(String name) {
        long[] rt = {0};
        RtHalf h = (RtHalf) Proxy.newProxyInstance(RtHalf.class.getClassLoader(), new Class<?>[] {RtHalf.class}, (p, meth, a) -> {
            switch (meth.getName()) {
                case "rtHeartbeatNs":
                    return rt[0];
                case "runtimeHeartbeat":
                    return null;
                case "hashCode":
                    return System.identityHashCode(p);
                case "equals":
                    return p == a[0];
                default:
                    throw new UnsupportedOperationException(meth.getName());
            }
        });
        hb.put(h, rt);
        names.put(h, name);
        m.watch(name, h, 100, now);
        return h;
    }

    /** {@code ms} of supervision at its period; the halves in {@code alive} cycle meanwhile. */
    private void run(long ms, RtHalf... alive) {
        for (long t = 0; t < ms; t += 20) {
            now += 20_000_000L;
            for (RtHalf h : alive) {
                hb.get(h)[0] = now - 1_000_000L;
            }
            m.check(now);
        }
    }

    @Test
    void oneHungHalfIsReportedWithinItsTimeoutWhileTheOthersCycle() {
        RtHalf a = half("a");
        RtHalf b = half("b");
        run(100, a, b);
        run(140, a); // b stops
        assertEquals(1, hung.size(), hung.toString());
        assertTrue(hung.get(0).startsWith("b: hung: no RT heartbeat for 1"), hung.toString());
    }

    @Test
    void aStallOfTheSupervisorItselfIsNotCounted() {
        RtHalf a = half("a");
        run(100, a);
        now += 300_000_000L; // the JVM stalled 300 ms (no checks), the half too
        m.check(now);
        run(100, a); // everything goes on after it
        assertEquals(List.of(), hung);
    }

    @Test
    void everyHalfSilentAtOnceIsTheMachineUntilFiveTimeouts() {
        RtHalf a = half("a");
        RtHalf b = half("b");
        run(100, a, b);
        run(300); // every half silent for 300 ms while the supervisor runs: the machine
        assertEquals(List.of(), hung);
        run(100, a, b);
        run(520); // silent for 5 timeouts: reported anyway
        assertEquals(2, hung.size(), hung.toString());
        assertTrue(hung.get(0).contains("every half silent"), hung.toString());
    }

    /** Issue 15 finding 5: an output damaged while its producer runs is that producer's fault, once. */
    @Test
    void aDamagedOutputIsReportedOnceWithinOnePeriod() {
        RtHalf a = half("a");
        String[] damage = {null};
        m.watch("a", a, 100, now, () -> damage[0]);
        run(100, a);
        assertEquals(List.of(), hung);
        damage[0] = "output a.y damaged while running (magic 0x0)";
        run(20, a);
        assertEquals(List.of("a: output a.y damaged while running (magic 0x0)"), hung);
        run(200, a);
        assertEquals(1, hung.size(), "reported once: " + hung);
    }
}
