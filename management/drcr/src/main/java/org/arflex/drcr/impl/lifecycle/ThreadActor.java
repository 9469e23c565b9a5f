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
    /** When the running task began (System.nanoTime), 0 when the actor is idle. */
    private volatile long taskStartNs;
    /** The running task was reported by {@link #watch} already. */
    private volatile boolean taskReported;

    public ThreadActor(Consumer<String> log) {
        this.log = log;
        executor = new ScheduledThreadPoolExecutor(1, r -> {
            Thread t = new Thread(r, THREAD_NAME);
            t.setDaemon(true);
            thread = t;
            return t;
        }) {
            @Override
            protected void beforeExecute(Thread t, Runnable r) {
                taskReported = false;
                taskStartNs = System.nanoTime();
            }

            @Override
            protected void afterExecute(Runnable r, Throwable t) {
                taskStartNs = 0;
            }
        };
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

    /**
     * From another thread (the DRCR's ticker): when the actor's current task has run longer than
     * {@code thresholdMs}, logs once where it is ("an actor task has run N ms, at ..."), the
     * DRCR's frames of the actor thread's stack. What a supervision stall's line alone cannot say.
     *
     * @return the frames logged, or null when nothing was reported
     */
    public String watch(long thresholdMs) {
        long s = taskStartNs;
        Thread t = thread;
        if (s == 0 || t == null || taskReported) {
            return null;
        }
        long ran = System.nanoTime() - s;
        if (ran < thresholdMs * 1_000_000L) {
            return null;
        }
        StringBuilder at = new StringBuilder();
        int n = 0;
        for (StackTraceElement e : t.getStackTrace()) {
            if (n < 6 && (e.getClassName().startsWith("org.arflex.") || n == 0)) {
                at.append(n++ == 0 ? "" : " < ").append(e.getClassName().replaceFirst("^org\\.arflex\\.drcr\\.impl\\.", ""))
                        .append('.').append(e.getMethodName()).append(':').append(e.getLineNumber());
            }
        }
        if (taskStartNs != s) {
            return null; // that task ended meanwhile: its stack is another's
        }
        taskReported = true;
        String frames = at.toString();
        log.accept("arflex: an actor task has run " + ran / 1_000_000L + " ms, at " + frames);
        return frames;
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
