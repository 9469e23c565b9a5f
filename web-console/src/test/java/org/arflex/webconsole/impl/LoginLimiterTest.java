package org.arflex.webconsole.impl;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertNotNull;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.time.Clock;
import java.time.Duration;
import java.time.Instant;
import java.time.ZoneId;
import java.time.ZoneOffset;
import org.junit.jupiter.api.Test;

/** Back-off of failed logins per client and over all clients, on an injected clock. */
class LoginLimiterTest {
    /** A clock the test moves. */
    static final class TestClock extends Clock {
        Instant now = Instant.parse("2026-12-07T21:00:00Z");

        void advance(Duration d) {
            now = now.plus(d);
        }

        @Override
        public ZoneId getZone() {
            return ZoneOffset.UTC;
        }

        @Override
        public Clock withZone(ZoneId zone) {
            return this;
        }

        @Override
        public Instant instant() {
            return now;
        }
    }

    @Test
    void pastTheFreeFailuresEachFailureDoublesTheLock() {
        TestClock clock = new TestClock();
        LoginLimiter l = new LoginLimiter(clock, 3, 100, Duration.ofSeconds(1), Duration.ofSeconds(10));
        for (int i = 0; i < 3; i++) {
            assertNull(l.check("a"), "free failure " + i);
            l.failed("a");
        }
        assertNull(l.check("a"));
        l.failed("a");
        LoginLimiter.Lock lock = l.check("a");
        assertNotNull(lock);
        assertEquals(Duration.ofSeconds(1), lock.retryAfter());
        assertEquals(4, lock.failures());
        assertTrue(lock.scope().contains("client a"), lock.scope());
        assertNull(l.check("b"), "another client is not held by a's lock");
        clock.advance(Duration.ofSeconds(1));
        assertNull(l.check("a"));
        l.failed("a");
        assertEquals(Duration.ofSeconds(2), l.check("a").retryAfter());
        clock.advance(Duration.ofSeconds(2));
        l.failed("a");
        assertEquals(Duration.ofSeconds(4), l.check("a").retryAfter());
        clock.advance(Duration.ofSeconds(4));
        l.failed("a");
        assertEquals(Duration.ofSeconds(8), l.check("a").retryAfter());
        clock.advance(Duration.ofSeconds(8));
        l.failed("a");
        assertEquals(Duration.ofSeconds(10), l.check("a").retryAfter(), "capped");
        assertEquals(10, l.check("a").retryAfterSeconds());
    }

    @Test
    void checksDuringALockDoNotLengthenItAndASuccessClearsTheClient() {
        TestClock clock = new TestClock();
        LoginLimiter l = new LoginLimiter(clock, 1, 100, Duration.ofSeconds(1), Duration.ofMinutes(5));
        l.failed("a");
        l.failed("a");
        for (int i = 0; i < 1000; i++) {
            assertNotNull(l.check("a"));
        }
        clock.advance(Duration.ofMillis(1000));
        assertNull(l.check("a"), "the lock ends when it said, however often it was asked");
        l.succeeded("a");
        l.failed("a");
        assertNull(l.check("a"), "after a success the free failures are there again");
    }

    @Test
    void theGlobalCountHoldsEveryClient() {
        TestClock clock = new TestClock();
        LoginLimiter l = new LoginLimiter(clock, 5, 10, Duration.ofSeconds(1), Duration.ofMinutes(5));
        for (int i = 0; i < 11; i++) {
            l.failed("10.0.0." + i);
        }
        LoginLimiter.Lock lock = l.check("10.0.0.99");
        assertNotNull(lock, "a fresh address is held by the global back-off");
        assertTrue(lock.scope().contains("all clients"), lock.scope());
        clock.advance(Duration.ofSeconds(1));
        assertNull(l.check("10.0.0.99"));
        // failures long ago no longer count
        clock.advance(Duration.ofMinutes(6));
        for (int i = 0; i < 10; i++) {
            l.failed("10.0.1." + i);
        }
        assertNull(l.check("10.0.0.99"));
    }

    @Test
    void manyAddressesDoNotBuyUnlimitedGuesses() {
        TestClock clock = new TestClock();
        LoginLimiter l = new LoginLimiter(clock, 0, Integer.MAX_VALUE, Duration.ofMinutes(1), Duration.ofMinutes(5));
        for (int i = 0; i < LoginLimiter.MAX_CLIENTS; i++) {
            l.failed("c" + i);
        }
        assertNotNull(l.check("c0"));
        l.failed("newcomer-1");
        assertNotNull(l.check("newcomer-2"), "when every entry is locked, new clients share one locked entry");
    }
}
