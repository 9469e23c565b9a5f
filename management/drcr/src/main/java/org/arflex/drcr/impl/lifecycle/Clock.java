package org.arflex.drcr.impl.lifecycle;

/** Monotonic time, injected so tests run on a simulated clock. */
public interface Clock {
    /** Milliseconds on a monotonic clock. */
    long millis();

    /** The system's monotonic clock. */
    Clock SYSTEM = () -> System.nanoTime() / 1_000_000L;
}
