package org.arflex.drcr.impl.shell;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.concurrent.TimeUnit;
import java.util.concurrent.atomic.AtomicBoolean;
import java.util.concurrent.atomic.AtomicInteger;
import java.util.concurrent.atomic.AtomicLong;
import org.junit.jupiter.api.Test;

/** The wait of arflex:await: woken by changes, ended by its deadline; no test sleeps. */
class CellWatchTest {

    private static final long S = 1_000_000_000L;

    @Test
    void aConditionThatHoldsReturnsAtOnce() throws Exception {
        CellWatch w = new CellWatch(() -> 0);
        CellWatch.Outcome<String> o = w.await(() -> "ACTIVE", "ACTIVE"::equals, 0);
        assertTrue(o.met());
        assertEquals("ACTIVE", o.last());
    }

    @Test
    void aChangeFromAnotherThreadWakesTheWaiter() throws Exception {
        CellWatch w = new CellWatch();
        AtomicBoolean active = new AtomicBoolean();
        AtomicInteger probes = new AtomicInteger();
        Thread[] other = new Thread[1];
        // the first look starts the change (which may be signalled before the waiter waits); the
        // waiter can only return through it (the timeout is an hour)
        CellWatch.Outcome<Boolean> o = w.await(() -> {
            boolean now = active.get(); // read before the change can happen: the first look sees false
            if (probes.getAndIncrement() == 0) {
                other[0] = new Thread(() -> {
                    active.set(true);
                    w.changed();
                });
                other[0].start();
            }
            return now;
        }, Boolean::booleanValue, TimeUnit.HOURS.toNanos(1));
        other[0].join();
        assertTrue(o.met());
        assertTrue(probes.get() >= 2, "looked " + probes.get() + " times");
    }

    @Test
    void theDeadlineEndsTheWaitWithTheLastValue() throws Exception {
        AtomicLong clock = new AtomicLong(5 * S);
        CellWatch w = new CellWatch(clock::get);
        AtomicInteger probes = new AtomicInteger();
        // each look takes 10 s of the test's clock and sees a change (so nothing blocks)
        CellWatch.Outcome<Integer> o = w.await(() -> {
            clock.addAndGet(10 * S);
            w.changed();
            return probes.incrementAndGet();
        }, n -> false, 25 * S);
        assertFalse(o.met());
        assertEquals(3, o.last(), "looked at 10, 20 and 30 s");
        assertEquals(30 * S, o.waitedNs());
    }

    @Test
    void aConditionMetAtTheLastLookCounts() throws Exception {
        AtomicLong clock = new AtomicLong();
        CellWatch w = new CellWatch(clock::get);
        CellWatch.Outcome<Long> o = w.await(() -> {
            clock.addAndGet(20 * S);
            w.changed();
            return clock.get();
        }, t -> t >= 40 * S, 30 * S);
        assertTrue(o.met());
        assertEquals(40 * S, o.waitedNs());
    }
}
