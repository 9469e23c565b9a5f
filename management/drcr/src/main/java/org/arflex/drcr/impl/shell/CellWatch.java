package org.arflex.drcr.impl.shell;

import java.util.function.LongSupplier;
import java.util.function.Predicate;
import java.util.function.Supplier;

/**
 * Waiting for a condition on the cell without polling: {@link #changed()} is called on every
 * change of the cell (the DRCR's change listener), and {@link #await} looks again only then, or
 * gives up at its deadline. The condition is looked at outside this object's lock: it may call
 * into the DRCR's actor, whose thread calls {@link #changed()}.
 */
public final class CellWatch {

    private final LongSupplier nanos;
    private long changes;

    /** A watch on {@link System#nanoTime()}. */
    public CellWatch() {
        this(System::nanoTime);
    }

    /** A watch on the given monotonic clock (ns); tests drive it. */
    public CellWatch(LongSupplier nanos) {
        this.nanos = nanos;
    }

    /** The outcome of a wait: the last value looked at and whether it met the condition. */
    public record Outcome<T>(T last, boolean met, long waitedNs) {
    }

    /** The cell changed: every waiter looks at its condition again. */
    public synchronized void changed() {
        changes++;
        notifyAll();
    }

    /**
     * Looks at {@code probe} now and after every change until {@code done} holds for what it
     * returned or {@code timeoutNs} has passed.
     *
     * @throws InterruptedException when the waiting thread is interrupted (the shell stops)
     */
    public <T> Outcome<T> await(Supplier<T> probe, Predicate<T> done, long timeoutNs) throws InterruptedException {
        long start = nanos.getAsLong();
        while (true) {
            long seen;
            synchronized (this) {
                seen = changes;
            }
            T v = probe.get();
            long waited = nanos.getAsLong() - start;
            if (done.test(v)) {
                return new Outcome<>(v, true, waited);
            }
            long left = timeoutNs - waited;
            if (left <= 0) {
                return new Outcome<>(v, false, waited);
            }
            synchronized (this) {
                // a change between the probe and here is not missed: 'changes' moved on
                if (changes == seen) {
                    wait(Math.max(1, left / 1_000_000), 0);
                }
            }
        }
    }
}
