package org.arflex.drcr.impl.lifecycle;

/**
 * The one thread on which every lifecycle change happens (as Felix SCR's
 * ComponentActorExecutor). Other threads submit work; work runs in submission order. Timers
 * run on the same thread.
 */
public interface Actor {

    /** Name of the actor thread in the real runtime. */
    String THREAD_NAME = "arflex-drcr-actor";

    /** Runs {@code r} on the actor thread, after what was submitted before. */
    void submit(Runnable r);

    /**
     * Runs {@code r} on the actor thread after {@code delayMs}.
     *
     * @return a handle that cancels the timer if it has not run yet
     */
    Cancellable schedule(Runnable r, long delayMs);

    /** True when the caller is the actor thread. */
    boolean inActor();

    /** The clock the actor's timers follow. */
    Clock clock();

    /**
     * Runs {@code c} on the actor thread and waits up to {@code timeoutMs} for its result
     * (directly when already on the actor thread). Exceptions of {@code c} are rethrown.
     */
    <T> T call(java.util.concurrent.Callable<T> c, long timeoutMs);

    /** Throws IllegalStateException unless called on the actor thread. */
    default void checkThread() {
        if (!inActor()) {
            throw new IllegalStateException("lifecycle change outside the actor thread: "
                    + Thread.currentThread().getName());
        }
    }

    /** A pending timer. */
    interface Cancellable {
        /** Cancels the timer; no effect when it already ran. */
        void cancel();
    }
}
