package org.arflex.drcr.impl.lifecycle;

import java.util.concurrent.Callable;
import java.util.concurrent.ExecutionException;
import java.util.concurrent.Future;
import java.util.concurrent.ScheduledFuture;
import java.util.concurrent.ScheduledThreadPoolExecutor;
import java.util.concurrent.TimeUnit;
import java.util.concurrent.TimeoutException;
import java.util.function.Consumer;

/**
 * The real actor: one daemon thread named {@value Actor#THREAD_NAME}. A task that throws is
 * logged and does not kill the thread. The longest time a submitted task waited for the actor
 * (what a crash report or a shell command waits behind) is logged each time it grows beyond
 * {@link #LAG_LOG_MS}: "the actor answered after N ms (longest yet)" (issue 17's supervision
 * stall, read by the soak bench).
 */
public final class ThreadActor implements Actor {

    private final ScheduledThreadPoolExecutor executor;
    private volatile Thread thread;
    private final Consumer<String> log;
    /** A wait for the actor longer than this is logged when it is the longest yet. */
    static final long LAG_LOG_MS = 20;
    private long longestWaitNs = LAG_LOG_MS * 1_000_000L; // actor thread only

    public ThreadActor(Consumer<String> log) {
        this.log = log;
        executor = new ScheduledThreadPoolExecutor(1, r -> {
            Thread t = new Thread(r, THREAD_NAME);
            t.setDaemon(true);
            thread = t;
            return t;
        });
        executor.setRemoveOnCancelPolicy(true);
        executor.setExecuteExistingDelayedTasksAfterShutdownPolicy(false);
    }

    private Runnable guarded(Runnable r) {
        return () -> {
            try {
                r.run();
            } catch (RuntimeException | Error e) {
                log.accept("arflex: actor task failed: " + e);
            }
        };
    }

    @Override
    public void submit(Runnable r) {
        long queued = System.nanoTime();
        Runnable g = guarded(r);
        executor.execute(() -> {
            waited(queued);
            g.run();
        });
    }

    /** Logs the wait of a task that started now, when it is the longest yet (actor thread). */
    private void waited(long queuedNs) {
        long w = System.nanoTime() - queuedNs;
        if (w > longestWaitNs) {
            longestWaitNs = w;
            log.accept("arflex: the actor answered after " + w / 1_000_000L + " ms (longest yet)");
        }
    }

    @Override
    public Cancellable schedule(Runnable r, long delayMs) {
        ScheduledFuture<?> f = executor.schedule(guarded(r), Math.max(0, delayMs), TimeUnit.MILLISECONDS);
        return () -> f.cancel(false);
    }

    @Override
    public boolean inActor() {
        return Thread.currentThread() == thread;
    }

    @Override
    public Clock clock() {
        return Clock.SYSTEM;
    }

    /**
     * Runs {@code c} on the actor thread and waits for its result (from another thread), or
     * runs it directly when already on the actor thread.
     */
    @Override
    public <T> T call(Callable<T> c, long timeoutMs) {
        if (inActor()) {
            try {
                return c.call();
            } catch (RuntimeException e) {
                throw e;
            } catch (Exception e) {
                throw new IllegalStateException(e);
            }
        }
        long queued = System.nanoTime();
        Future<T> f = executor.submit(() -> {
            waited(queued);
            return c.call();
        });
        try {
            return f.get(timeoutMs, TimeUnit.MILLISECONDS);
        } catch (ExecutionException e) {
            if (e.getCause() instanceof RuntimeException re) {
                throw re;
            }
            throw new IllegalStateException(e.getCause());
        } catch (TimeoutException e) {
            throw new IllegalStateException("actor did not answer within " + timeoutMs + " ms");
        } catch (InterruptedException e) {
            Thread.currentThread().interrupt();
            throw new IllegalStateException("interrupted");
        }
    }

    /** Stops the thread after the work already submitted (waits up to {@code timeoutMs}). */
    public void shutdown(long timeoutMs) {
        executor.shutdown();
        try {
            if (!executor.awaitTermination(timeoutMs, TimeUnit.MILLISECONDS)) {
                executor.shutdownNow();
            }
        } catch (InterruptedException e) {
            executor.shutdownNow();
            Thread.currentThread().interrupt();
        }
    }
}
