package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.concurrent.atomic.AtomicInteger;
import org.junit.jupiter.api.Test;

/** {@link Polling#until}: returns only when the condition held (D82). */
class PollingTest {

    @Test
    void returnsOnceTheConditionHolds() {
        AtomicInteger polls = new AtomicInteger();
        Polling.until("the third poll", 10_000, () -> polls.incrementAndGet() == 3, () -> "");
        assertEquals(3, polls.get());
    }

    @Test
    void anInterruptedWaitFailsAndKeepsTheInterrupt() {
        Thread.currentThread().interrupt();
        try {
            AssertionError e = assertThrows(AssertionError.class,
                    () -> Polling.until("something that never holds", 10_000, () -> false, () -> ""));
            assertTrue(e.getMessage().contains("interrupted while waiting for something that never holds"), e.getMessage());
            assertTrue(Thread.currentThread().isInterrupted(), "the interrupt flag is kept");
        } finally {
            Thread.interrupted();
        }
    }

    @Test
    void aConditionInterruptedInsideFailsToo() {
        try {
            AssertionError e = assertThrows(AssertionError.class, () -> Polling.until("a reply", 10_000, () -> {
                throw new InterruptedException("reader interrupted");
            }, () -> ""));
            assertTrue(e.getMessage().contains("interrupted while waiting for a reply"), e.getMessage());
            assertTrue(Thread.currentThread().isInterrupted(), "the interrupt flag is kept");
        } finally {
            Thread.interrupted();
        }
    }

    @Test
    void aTimeoutFailsWithTheLastErrorAndTheAccount() {
        AssertionError e = assertThrows(AssertionError.class, () -> Polling.until("x", 30, () -> {
            throw new IllegalStateException("not yet");
        }, () -> " [account]"));
        assertTrue(e.getMessage().contains("timed out after 30 ms waiting for x (last error java.lang.IllegalStateException: not yet) [account]"),
                e.getMessage());
    }
}
