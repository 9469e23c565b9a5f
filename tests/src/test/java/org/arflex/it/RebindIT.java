package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.Map;
import org.junit.jupiter.api.Test;

/**
 * Live rewiring: a running component whose optional input gains or loses a provider is bound
 * and unbound while it runs (plan action REBIND), not restarted. The debug monitor has two
 * optional inputs (sample-counter.count, sample-scaler.y), so it is Active alone; the provider
 * arriving later must reach it through a BIND to the same process, and its values must then
 * flow through. Guards the regression where every rewire restarted the consumer (and a moving
 * component then waited for an operator reset).
 */
class RebindIT {

    static final long T = 30_000;

    @Test
    void anOptionalInputIsBoundAndUnboundWhileTheConsumerKeepsRunning() throws Exception {
        try (Runtime rt = new Runtime("rebind")) {
            long mon = rt.installAndStart(DebugMonitorIT.DEBUGMON);
            rt.awaitState("ACTIVE", T, "debug-monitor");
            long pid = rt.pid("debug-monitor");

            String plan = rt.cmd("arflex:plan install " + CellIT.COUNTER.toUri());
            assertTrue(plan.lines().anyMatch(l -> l.contains("REBIND") && l.contains("debug-monitor")), plan);
            assertTrue(plan.lines().noneMatch(l -> l.contains("RESTART")), plan);

            long counter = rt.installAndStart(CellIT.COUNTER);
            rt.awaitState("ACTIVE", T, "sample-counter");
            rt.waitUntil("debug-monitor bound to sample-counter.count", T,
                    () -> rt.cmd("arflex:bindings").contains("debug-monitor.m0 <- sample-counter.count"));
            assertEquals(pid, rt.pid("debug-monitor"), "the monitor was restarted instead of rebound");

            // Values flow through the live binding: the monitor's m0_last repeats the counter.
            try (DebugMonitorIT.StatePort src = new DebugMonitorIT.StatePort(rt.segment("sample-counter", "count"));
                    DebugMonitorIT.StatePort m0 = new DebugMonitorIT.StatePort(rt.segment("debug-monitor", "m0_last"))) {
                rt.waitUntil("the monitor repeats a counter value", T, () -> {
                    Ports.Sample a = m0.read();
                    Ports.Sample b = src.read();
                    return a != null && b != null && a.seq() > 0 && a.seq() <= b.seq();
                });
            }

            // The provider goes: the monitor is unbound, still the same process, still Active.
            assertEquals("", rt.cmd("uninstall " + counter));
            rt.waitUntil("sample-counter gone", T, () -> {
                Map<String, Object> c = rt.instance("sample-counter");
                return c == null || "DESTROYED".equals(c.get("state"));
            });
            Map<String, Object> i = rt.instance("debug-monitor");
            assertEquals("ACTIVE", i.get("state"), String.valueOf(i));
            assertEquals(pid, rt.pid("debug-monitor"), "the monitor was restarted when its provider left");
            assertTrue(!rt.cmd("arflex:bindings").contains("debug-monitor.m0"), rt.cmd("arflex:bindings"));
            assertEquals("", rt.cmd("uninstall " + mon));
        }
    }
}
