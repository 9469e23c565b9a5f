package org.arflex.drcr.impl.runtime;

import java.io.IOException;
import java.util.ArrayList;
import java.util.Collection;
import java.util.HashMap;
import java.util.IdentityHashMap;
import java.util.List;
import java.util.Map;
import java.util.Set;
import java.util.concurrent.CompletableFuture;
import java.util.concurrent.ConcurrentHashMap;
import java.util.concurrent.Executor;
import java.util.concurrent.RejectedExecutionException;
import java.util.function.Consumer;
import org.arflex.drcr.impl.lifecycle.Actor;
import org.arflex.drcr.impl.supervisor.HeartbeatMonitor;
import org.arflex.drcr.impl.supervisor.RtHalf;

/**
 * Stops RT halves away from the actor thread (issue 17 finding 1: a frozen half held the actor,
 * and with it every crash report and the shell, for up to 12 s). The actor detaches the halves
 * a plan stops and hands them over as one batch; a stop thread runs the batch's three sweeps
 * (every UNBIND, then the two-cycle wait of each, then STOP/SHUTDOWN/SIGTERM/SIGKILL in the
 * plan's stop order), each mailbox command with a short deadline and the process with the
 * shutdown deadline; then the outcome goes back to the actor, which only records it (log,
 * reason, output segments of destroyed instances, starts that waited for the name).
 *
 * <p>Bookkeeping ({@link #pending}, {@link #stopping}) belongs to the actor thread. With an
 * executor that runs inline ({@code Runnable::run}, unit tests) a batch completes before
 * {@link #submit} returns, as stops did before.
 */
final class Stops {

    /** Deadline of each UNBIND on the way out. */
    static final long UNBIND_MS = 250;
    /** How long a stop waits for consumers' UNBINDs the actor did not wait for (the call timeout). */
    static final long UNBIND_WAIT_MS = 2_500;

    /** One RT half on its way out, detached from its instance on the actor. */
    static final class Going {
        final Instance inst;
        final RtHalf half;
        /** Inputs bound when it was detached: unbound first. */
        final List<String> inputs;
        /** How long the RT loop may take for its two cycles after the UNBINDs. */
        final long settleMs;
        /** Why it stops (the plan's reason). */
        final String why;
        volatile boolean unanswered;
        /** The RT loop's cycle count right after the UNBINDs (stop thread). */
        long since = -1;
        /** How it ended (ProcessRtHalf.shutdown), set by the stop thread. */
        volatile String outcome;

        Going(Instance inst, RtHalf half, List<String> inputs, long settleMs, String why) {
            this.inst = inst;
            this.half = half;
            this.inputs = List.copyOf(inputs);
            this.settleMs = settleMs;
            this.why = why;
        }

        /** True when it had to be terminated by a signal (the outcome says after how long). */
        boolean forced() {
            String o = outcome;
            return o != null && (o.startsWith("killed") || o.startsWith("exited on SIGTERM"));
        }
    }

    /** The halves one plan stops. */
    static final class Batch {
        final List<Going> halves;
        /**
         * Completes once every half of the batch has exited or one of them did not answer (it
         * is being terminated): what a caller that wants an orderly stop behind it waits for,
         * without waiting out a frozen process.
         */
        final CompletableFuture<Void> settled = new CompletableFuture<>();
        /** Completes when the actor has recorded every outcome. */
        final CompletableFuture<Void> done = new CompletableFuture<>();

        /**
         * Consumers' UNBINDs of the same plan still unanswered when it was submitted (D39): the
         * providers of this batch are stopped only once they are answered (or failed, or the
         * call timeout passed), so no consumer reads a provider while it goes away.
         */
        final List<CompletableFuture<Void>> before;

        Batch(List<Going> halves, List<CompletableFuture<Void>> before) {
            this.halves = List.copyOf(halves);
            this.before = List.copyOf(before);
        }
    }

    private final Actor actor;
    private final Executor executor;
    private final HeartbeatMonitor monitor;
    private final long shutdownMs;
    private final Consumer<String> log;
    private final Consumer<Batch> recorder;
    /** Instance name -> halves of that name still on their way out (actor thread). */
    private final Map<String, Integer> pending = new HashMap<>();
    /** Instance -> the batch its half is stopping in (actor thread). */
    private final Map<Instance, Batch> stopping = new IdentityHashMap<>();
    private final Set<Batch> inFlight = ConcurrentHashMap.newKeySet();

    /**
     * @param recorder runs on the actor with a finished batch (every outcome set), before
     *                 {@link Batch#done} completes
     */
    Stops(Actor actor, Executor executor, HeartbeatMonitor monitor, long shutdownMs, Consumer<String> log,
          Consumer<Batch> recorder) {
        this.actor = actor;
        this.executor = executor;
        this.monitor = monitor;
        this.shutdownMs = shutdownMs;
        this.log = log;
        this.recorder = recorder;
    }

    /** Hands detached halves to a stop thread (actor thread); empty: nothing happens. */
    Batch submit(List<Going> halves) {
        return submit(halves, List.of());
    }

    /** The same, after the consumers' UNBINDs in {@code before} are answered (see {@link Batch#before}). */
    Batch submit(List<Going> halves, List<CompletableFuture<Void>> before) {
        actor.checkThread();
        Batch b = new Batch(halves, before);
        if (halves.isEmpty()) {
            b.settled.complete(null);
            b.done.complete(null);
            return b;
        }
        for (Going g : halves) {
            pending.merge(g.inst.name, 1, Integer::sum);
            stopping.put(g.inst, b);
        }
        inFlight.add(b);
        try {
            executor.execute(() -> run(b));
        } catch (RejectedExecutionException e) {
            // the runtime is stopping and its stop threads are gone: stop here rather than leak
            log.accept("arflex: stop thread refused (" + e.getMessage() + "); stopping on the actor");
            run(b);
        }
        return b;
    }

    /** Whether a half of that name is still on its way out (actor thread). */
    boolean pending(String name) {
        return pending.containsKey(name);
    }

    /** Whether this instance's half is on its way out (actor thread). */
    boolean stopping(Instance inst) {
        return stopping.containsKey(inst);
    }

    /** Completes when the stops of these instances have settled (see {@link Batch#settled}); actor thread. */
    CompletableFuture<Void> settled(Collection<Instance> instances) {
        return all(instances, b -> b.settled);
    }

    /**
     * Completes when the stops of these instances are recorded (see {@link Batch#done}): their
     * names are no longer {@link #pending}; at once for an instance not stopping. Actor thread.
     */
    CompletableFuture<Void> recorded(Collection<Instance> instances) {
        actor.checkThread();
        return all(instances, b -> b.done);
    }

    /** {@code which} future of the batch each of these instances stops in, all of them. */
    private CompletableFuture<Void> all(Collection<Instance> instances,
                                        java.util.function.Function<Batch, CompletableFuture<Void>> which) {
        return CompletableFuture.allOf(instances.stream().map(stopping::get).filter(java.util.Objects::nonNull)
                .map(which).toArray(CompletableFuture[]::new));
    }

    /** Completes when every batch submitted so far is recorded (any thread). */
    CompletableFuture<Void> idle() {
        return CompletableFuture.allOf(inFlight.stream().map(b -> b.done).toArray(CompletableFuture[]::new));
    }

    /** Number of batches not yet recorded. */
    int inFlight() {
        return inFlight.size();
    }

    /** The stop thread's part. Never throws; every half ends with an outcome. */
    private void run(Batch b) {
        try {
            // 0. The consumers that had not answered their UNBIND on the actor: wait for them.
            if (!b.before.isEmpty()) {
                try {
                    CompletableFuture.allOf(b.before.toArray(CompletableFuture[]::new))
                            .get(UNBIND_WAIT_MS, java.util.concurrent.TimeUnit.MILLISECONDS);
                } catch (java.util.concurrent.ExecutionException | java.util.concurrent.TimeoutException e) {
                    // refused or unanswered: that consumer is restarted by the failure path
                } catch (InterruptedException e) {
                    Thread.currentThread().interrupt();
                }
            }
            // 1. Every input unbound, so every consumer runs its safe behaviour from now on.
            for (Going g : b.halves) {
                for (String port : g.inputs) {
                    try {
                        g.half.unbind(port, UNBIND_MS);
                    } catch (IOException | RuntimeException e) {
                        log.accept("arflex: " + g.inst.name + ": " + e.getMessage() + "; not waiting for it");
                        g.unanswered = true;
                        break;
                    }
                }
                g.since = g.inputs.isEmpty() || g.unanswered ? -1 : g.half.cycles();
            }
            if (b.halves.stream().anyMatch(g -> g.unanswered)) {
                b.settled.complete(null);
            }
            // 2. Each half that took its UNBINDs runs two more cycles (the waits overlap: they
            // count from the UNBIND). A half that stops while it settles stays watched, so the
            // runtime heartbeat goes on and it does not latch safe mode for a lost runtime.
            for (Going g : b.halves) {
                if (!g.inputs.isEmpty() && !g.unanswered && !g.half.awaitCycles(g.since, 2, g.settleMs)) {
                    log.accept("arflex: " + g.inst.name + ": no RT cycle after UNBIND; stopping anyway");
                }
            }
            // 3. STOP, SHUTDOWN, the process gone, in the plan's stop order.
            for (Going g : b.halves) {
                monitor.unwatch(g.half);
                g.outcome = g.half.shutdown(shutdownMs, () -> {
                    g.unanswered = true;
                    b.settled.complete(null);
                });
            }
        } catch (RuntimeException | Error e) {
            log.accept("arflex: stopping " + names(b) + " failed: " + e + "; killing what is left");
            for (Going g : b.halves) {
                if (g.outcome == null) {
                    monitor.unwatch(g.half);
                    g.half.kill();
                    g.half.exit().orTimeout(shutdownMs, java.util.concurrent.TimeUnit.MILLISECONDS)
                            .exceptionally(x -> null).join();
                    g.half.cleanup();
                    g.outcome = "killed after a failure of its stop (" + e + ")";
                }
            }
        } finally {
            b.settled.complete(null);
            deliver(b);
        }
    }

    private void deliver(Batch b) {
        if (actor.inActor()) {
            record(b);
            return;
        }
        try {
            actor.submit(() -> record(b));
        } catch (RejectedExecutionException e) {
            // the actor is gone (runtime stopped): the processes are, too; nothing to record
            log.accept("arflex: " + names(b) + " stopped after the actor ended: "
                    + b.halves.stream().map(g -> g.outcome).toList());
            inFlight.remove(b);
            b.done.complete(null);
        }
    }

    private void record(Batch b) {
        for (Going g : b.halves) {
            pending.computeIfPresent(g.inst.name, (k, n) -> n > 1 ? n - 1 : null);
            stopping.remove(g.inst, b);
        }
        try {
            recorder.accept(b);
        } catch (RuntimeException e) {
            log.accept("arflex: recording the stop of " + names(b) + " failed: " + e);
        } finally {
            inFlight.remove(b);
            b.done.complete(null);
        }
    }

    private static List<String> names(Batch b) {
        return b.halves.stream().map(g -> g.inst.name).toList();
    }
}
