package org.arflex.drcr.impl.lifecycle;

import java.util.ArrayDeque;
import java.util.ArrayList;
import java.util.Comparator;
import java.util.Deque;
import java.util.List;

/**
 * A steppable actor for deterministic tests: nothing runs until the test calls
 * {@link #runAll()} or {@link #advance(long)}; the clock moves only when the test says so. The
 * calling test thread counts as the actor thread while it steps.
 */
public final class ManualActor implements Actor {

    private final Deque<Runnable> queue = new ArrayDeque<>();
    private final List<Timer> timers = new ArrayList<>();
    private long now;
    private volatile boolean stepping;
    /** The thread that steps (the test's); another thread (a stop thread) is never the actor. */
    private volatile Thread stepper;
    private long seq;

    private final class Timer implements Cancellable {
        final long due;
        final long order = seq++;
        final Runnable r;
        boolean cancelled;

        Timer(long due, Runnable r) {
            this.due = due;
            this.r = r;
        }

        @Override
        public void cancel() {
            cancelled = true;
            timers.remove(this);
        }
    }

    /** May be called from any thread (a stop thread records its outcome this way). */
    @Override
    public void submit(Runnable r) {
        synchronized (queue) {
            queue.addLast(r);
        }
    }

    @Override
    public Cancellable schedule(Runnable r, long delayMs) {
        Timer t = new Timer(now + Math.max(0, delayMs), r);
        timers.add(t);
        return t;
    }

    @Override
    public boolean inActor() {
        return stepping && Thread.currentThread() == stepper;
    }

    @Override
    public Clock clock() {
        return () -> now;
    }

    /** Runs submitted work until the queue is empty (timers that are due included). */
    public int runAll() {
        int n = 0;
        stepping = true;
        stepper = Thread.currentThread();
        try {
            while (true) {
                Runnable r;
                synchronized (queue) {
                    r = queue.pollFirst();
                }
                if (r == null) {
                    Timer due = timers.stream().filter(t -> t.due <= now)
                            .min(Comparator.comparingLong((Timer t) -> t.due).thenComparingLong(t -> t.order)).orElse(null);
                    if (due == null) {
                        return n;
                    }
                    timers.remove(due);
                    r = due.r;
                }
                r.run();
                n++;
            }
        } finally {
            stepping = false;
        }
    }

    /** Moves the clock by {@code ms}, firing timers in due order. */
    public void advance(long ms) {
        long end = now + ms;
        while (true) {
            runAll();
            Timer next = timers.stream().filter(t -> t.due <= end)
                    .min(Comparator.comparingLong((Timer t) -> t.due).thenComparingLong(t -> t.order)).orElse(null);
            if (next == null) {
                break;
            }
            now = Math.max(now, next.due);
        }
        now = end;
        runAll();
    }

    /** Runs {@code r} as if on the actor thread (for test setup). */
    public void onActor(Runnable r) {
        boolean was = stepping;
        stepping = true;
        stepper = Thread.currentThread();
        try {
            r.run();
        } finally {
            stepping = was;
        }
    }

    @Override
    public <T> T call(java.util.concurrent.Callable<T> c, long timeoutMs) {
        boolean was = stepping;
        stepping = true;
        stepper = Thread.currentThread();
        try {
            return c.call();
        } catch (RuntimeException e) {
            throw e;
        } catch (Exception e) {
            throw new IllegalStateException(e);
        } finally {
            stepping = was;
        }
    }

    /** Pending timers. */
    public int pendingTimers() {
        return timers.size();
    }

    /** Current simulated time. */
    public long now() {
        return now;
    }
}
