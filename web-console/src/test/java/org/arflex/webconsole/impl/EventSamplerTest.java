package org.arflex.webconsole.impl;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.time.Duration;
import java.util.List;
import java.util.Map;
import org.junit.jupiter.api.Test;

/** Sampling and counting of like events per key and window. */
class EventSamplerTest {

    @Test
    void firstFewPerKeyThenCountedAndOneSummaryWhenTheWindowIsOver() {
        LoginLimiterTest.TestClock clock = new LoginLimiterTest.TestClock();
        EventSampler s = new EventSampler(clock, Duration.ofMinutes(1), 3, 100, 8);
        int written = 0;
        for (int i = 0; i < 1400; i++) {
            written += s.admit("http://evil.example") ? 1 : 0;
        }
        assertEquals(3, written);
        assertTrue(s.admit("http://other.example"), "another key has its own samples");
        assertEquals(Map.of("http://evil.example", 1397L), s.pending());
        assertEquals(List.of(), s.due(), "nothing before the minute is over");
        clock.advance(Duration.ofSeconds(61));
        List<EventSampler.Summary> due = s.due();
        assertEquals(1, due.size());
        assertEquals("http://evil.example", due.get(0).key());
        assertEquals(1397, due.get(0).notWritten());
        assertEquals(1400, due.get(0).seen());
        assertEquals(Duration.ofMinutes(1), Duration.between(due.get(0).from(), due.get(0).to()));
        assertEquals(List.of(), s.due(), "handed out once");
        assertTrue(s.admit("http://evil.example"), "a new minute, new samples");
    }

    @Test
    void boundedOverAllKeysAndInTheNumberOfKeys() {
        LoginLimiterTest.TestClock clock = new LoginLimiterTest.TestClock();
        EventSampler s = new EventSampler(clock, Duration.ofMinutes(1), 5, 20, 16);
        int written = 0;
        for (int i = 0; i < 10_000; i++) {
            written += s.admit("http://o" + i + ".example") ? 1 : 0;
        }
        assertEquals(20, written);
        Map<String, Long> pending = s.pending();
        assertTrue(pending.size() <= 17, pending.toString());
        assertTrue(pending.containsKey(EventSampler.OTHER));
        assertEquals(10_000 - 20, pending.values().stream().mapToLong(Long::longValue).sum());
        clock.advance(Duration.ofMinutes(5));
        assertTrue(s.due().size() <= 17);
    }

    @Test
    void drainHandsOutTheCurrentWindowToo() {
        LoginLimiterTest.TestClock clock = new LoginLimiterTest.TestClock();
        EventSampler s = new EventSampler(clock, Duration.ofMinutes(1), 1, 10, 4);
        s.admit("a");
        assertFalse(s.admit("a"));
        List<EventSampler.Summary> d = s.drain();
        assertEquals(1, d.size());
        assertEquals(1, d.get(0).notWritten());
        assertEquals(Map.of(), s.pending());
    }
}
