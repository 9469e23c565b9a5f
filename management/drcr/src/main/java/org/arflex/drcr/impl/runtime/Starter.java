package org.arflex.drcr.impl.runtime;

import java.io.IOException;
import java.util.ArrayList;
import java.util.HashMap;
import java.util.Map;
import java.util.List;
import java.util.concurrent.CompletableFuture;
import java.util.concurrent.Executor;
import java.util.function.Consumer;
import org.arflex.contract.Contract;
import org.arflex.drcr.impl.lifecycle.Actor;
import org.arflex.drcr.impl.lifecycle.State;
import org.arflex.drcr.impl.supervisor.HeartbeatMonitor;
import org.arflex.drcr.impl.supervisor.RtHalf;
import org.arflex.drcr.impl.supervisor.RtLauncher;
import org.arflex.planner.Planner;
import org.arflex.planner.Wire;

/**
 * Starts the RT half of one instance in two steps. On the actor: its output segments and the
 * spawn request (the control block's configuration and parameters). On a launch thread: the
 * spawn and the wait for READY, which may take hundreds of milliseconds (a simulator loading
 * its model) and must not hold crash handling, hang kills or the shell (issue 17). Back on the
 * actor: if the instance still wants exactly this start, a BIND per input of the planner's
 * current wiring, the parameters written while it started, the runtime heartbeat and START;
 * then the half is watched for hangs and its exit goes to {@link Failures}. A start that is no
 * longer wanted (uninstalled, updated, stopped by a plan while it launched) is stopped on a stop
 * thread; a start that fails goes to {@link Failures} as a crash would.
 */
final class Starter {

    private final Cell.Config cfg;
    private final Actor actor;
    private final RtLauncher launcher;
    private final HeartbeatMonitor monitor;
    private final Segments segments;
    private final Stops stops;
    private final Failures failures;
    private final Consumer<String> log;
    private final Executor launches;
    private final Planner planner;
    private final Runnable changed;
    private final Runnable resume;
    private int inFlight; // launches whose outcome is not recorded yet (guarded by this)
    private final Map<String, Integer> byName = new HashMap<>(); // launches in flight per name (actor)
    private final List<CompletableFuture<Void>> idleWaiters = new ArrayList<>();

    Starter(Cell.Config cfg, Actor actor, RtLauncher launcher, HeartbeatMonitor monitor, Segments segments, Stops stops,
            Failures failures, Consumer<String> log, Executor launches, Planner planner, Runnable changed,
            Runnable resume) {
        this.cfg = cfg;
        this.actor = actor;
        this.launcher = launcher;
        this.monitor = monitor;
        this.segments = segments;
        this.stops = stops;
        this.failures = failures;
        this.log = log;
        this.launches = launches;
        this.planner = planner;
        this.changed = changed;
        this.resume = resume;
    }

    /** Begins the start of {@code inst} on {@code cpu} (actor thread); see the class comment. */
    void start(Instance inst, int cpu) {
        Contract c = inst.contract;
        long t0 = cfg.monotonicNs().getAsLong();
        boolean resetRequired = c.movesHardware() && inst.everStarted;
        long[] params = inst.params.clone();
        RtLauncher.Spec spec;
        try {
            segments.ensure(inst);
            spec = new RtLauncher.Spec(cfg.runtimeId(), inst.objectId, inst.executable,
                    ControlSetup.config(c, cpu, cfg.noMlock()), ControlSetup.params(c, params), resetRequired,
                    cfg.readyTimeoutMs());
        } catch (IOException | RuntimeException e) {
            fail(inst, e);
            return;
        }
        long seq = ++inst.launchSeq;
        inst.launching = true;
        byName.merge(inst.name, 1, Integer::sum);
        synchronized (this) {
            inFlight++;
        }
        inst.life.reason("starting: spawned, waiting for READY");
        launches.execute(() -> {
            RtHalf half = null;
            Exception error = null;
            try {
                half = launcher.launch(spec);
            } catch (IOException | RuntimeException e) {
                error = e;
            }
            long tLaunched = cfg.monotonicNs().getAsLong();
            RtHalf h = half;
            Exception err = error;
            Runnable done = () -> launched(inst, seq, cpu, params, h, err, t0, tLaunched);
            if (actor.inActor()) {
                done.run(); // a launch executor that runs inline (tests)
            } else {
                actor.submit(done);
            }
        });
    }

    /**
     * True while a half of this name is being launched (actor thread): a start of the name, also
     * by a new instance after an uninstall, waits for it (the half owns the name's objects).
     */
    boolean launching(String name) {
        return byName.containsKey(name);
    }

    /** Completes when every launch begun so far has its outcome recorded (any thread). */
    synchronized CompletableFuture<Void> idle() {
        CompletableFuture<Void> f = new CompletableFuture<>();
        if (inFlight == 0) {
            f.complete(null);
        } else {
            idleWaiters.add(f);
        }
        return f;
    }

    /** The launch of {@code seq} ended (actor thread): finish it, or stop a half nobody wants. */
    private void launched(Instance inst, long seq, int cpu, long[] params, RtHalf half, Exception error, long t0,
                          long tLaunched) {
        try {
            record(inst, seq, cpu, params, half, error, t0, tLaunched);
        } finally {
            landed(inst.name);
        }
    }

    /** Bookkeeping of a launch whose outcome is being recorded (actor thread). */
    private void landed(String name) {
        byName.computeIfPresent(name, (k, n) -> n == 1 ? null : n - 1);
        List<CompletableFuture<Void>> done = List.of();
        synchronized (this) {
            if (--inFlight == 0) {
                done = List.copyOf(idleWaiters);
                idleWaiters.clear();
            }
        }
        done.forEach(f -> f.complete(null));
    }

    /** Where a change set's launch reports (actor thread): the READY half, or why there is none
     *  (with a half too when the half is READY but its ADOPT was refused). */
    interface Prepared {
        void ready(RtHalf half, Exception error, long spawnToReadyNs);
    }

    /**
     * A change set's launch (D35): the output segments and the spawn request on the actor, the
     * spawn and the wait for READY on the launch thread (one at a time, as every launch), the
     * outcome back on the actor to {@code done}. The half is neither bound nor started and the
     * instance is not touched otherwise: the change set starts it at its switch
     * ({@link #activate}) or stops it. Counted as a launch: a start of the name waits for it and
     * {@link #idle()} completes only after {@code done} ran.
     */
    void prepare(Instance inst, int cpu, Prepared done) {
        prepare(inst, cpu, null, done);
    }

    /**
     * As {@link #prepare(Instance, int, Prepared)}; with {@code adoptFrom} not null the READY
     * half is also told, on the launch thread, the state segment it adopts at its START (D41,
     * {@link StateTransfer}); a refused ADOPT reports the READY half together with the error,
     * for the caller to stop with whatever else it prepared.
     */
    void prepare(Instance inst, int cpu, String adoptFrom, Prepared done) {
        Contract c = inst.contract;
        RtLauncher.Spec spec;
        try {
            segments.ensure(inst);
            spec = new RtLauncher.Spec(cfg.runtimeId(), inst.objectId, inst.executable,
                    ControlSetup.config(c, cpu, cfg.noMlock()), ControlSetup.params(c, inst.params.clone()), false,
                    cfg.readyTimeoutMs());
        } catch (IOException | RuntimeException e) {
            done.ready(null, e, 0);
            return;
        }
        inst.launching = true;
        byName.merge(inst.name, 1, Integer::sum);
        synchronized (this) {
            inFlight++;
        }
        long t0 = cfg.monotonicNs().getAsLong();
        launches.execute(() -> {
            RtHalf half = null;
            Exception error = null;
            try {
                half = launcher.launch(spec);
                if (adoptFrom != null) {
                    try {
                        half.adopt(adoptFrom);
                    } catch (IOException | RuntimeException e) { // READY, but not with the state it continues
                        error = new IOException("its state block: " + e.getMessage(), e);
                    }
                }
            } catch (IOException | RuntimeException e) {
                error = e;
            }
            long took = cfg.monotonicNs().getAsLong() - t0;
            RtHalf h = half;
            Exception err = error;
            Runnable back = () -> {
                inst.launching = false;
                try {
                    done.ready(h, err, took);
                } finally {
                    landed(inst.name);
                }
            };
            if (actor.inActor()) {
                back.run();
            } else {
                actor.submit(back);
            }
        });
    }

    private void record(Instance inst, long seq, int cpu, long[] params, RtHalf half, Exception error, long t0,
                        long tLaunched) {
        inst.launching = false;
        if (seq != inst.launchSeq) {
            // a plan stopped the instance while it launched (a start of it since waits for this)
            if (half != null) {
                stops.submit(List.of(new Stops.Going(inst, half, List.of(), 0, "stopped while it started")));
            } else {
                resume.run();
            }
            changed.run();
            return;
        }
        boolean wanted = inst.half == null && inst.life.state() != State.DESTROYED
                && inst.life.state() != State.FAILED && inst.life.target() != State.DESTROYED
                && planner.active().contains(inst.name);
        if (!wanted) {
            if (half != null) {
                stops.submit(List.of(new Stops.Going(inst, half, List.of(), 0, "no longer wanted when it was ready")));
            } else {
                resume.run();
            }
            changed.run();
            return;
        }
        if (error != null) {
            fail(inst, error);
            resume.run();
            changed.run();
            return;
        }
        activate(inst, half, cpu, params, planner.current().wiringOf(inst.name), t0, tLaunched);
    }

    /**
     * Makes a READY half the instance's running half (actor thread): a BIND per input of
     * {@code wiring}, the parameters written since {@code params} were sent, the runtime
     * heartbeat, START; then ACTIVE, watched, its exit to {@link Failures}. A refused command
     * stops the half on a stop thread and fails the instance as a crash would.
     *
     * @return true when it runs
     */
    boolean activate(Instance inst, RtHalf half, int cpu, long[] params, List<Wire> wiring, long t0, long tLaunched) {
        return activate(inst, half, cpu, params, wiring, t0, tLaunched, e -> fail(inst, e));
    }

    /** Binds {@code half}'s inputs as {@code wiring} says, from scratch, and records them in {@code inst.bound}. */
    static void bind(Segments segments, Instance inst, RtHalf half, List<Wire> wiring) throws IOException {
        inst.bound.clear();
        for (Wire w : wiring) {
            String seg = segments.name(w.provider(), w.outPort());
            half.bind(w.inPort(), seg);
            inst.bound.put(w.inPort(), seg);
        }
    }

    /**
     * As above; a refused command stops the half and goes to {@code refused} instead of the
     * fault policy (an update's new half at its switch: the old half takes it back, D55).
     */
    boolean activate(Instance inst, RtHalf half, int cpu, long[] params, List<Wire> wiring, long t0, long tLaunched,
                     java.util.function.Consumer<Exception> refused) {
        try {
            bind(segments, inst, half, wiring);
            long[] now = inst.params;
            for (int i = 0; i < now.length && i < params.length; i++) {
                if (now[i] != params[i]) { // written while it started
                    half.setParam(i, now[i]);
                }
            }
            half.runtimeHeartbeat(cfg.monotonicNs().getAsLong());
            half.start();
        } catch (IOException | RuntimeException e) {
            // stopped and reaped on a stop thread; a restart of the name waits for it
            stops.submit(List.of(new Stops.Going(inst, half, List.of(), 0, "start failed")));
            refused.accept(e);
            changed.run();
            return false;
        }
        adopt(inst, half, cpu, "spawn to READY " + (tLaunched - t0) / 1000 + " us, bind+start "
                + (cfg.monotonicNs().getAsLong() - tLaunched) / 1000 + " us");
        return true;
    }

    /**
     * Makes a half that is bound and started already the instance's running half (actor thread):
     * ACTIVE, watched, its exit to {@link Failures}. {@link #activate} ends here; an update's
     * shadow run (D42, {@link ShadowRun}) bound and started its half itself and comes here at
     * the switch, with no second BIND or START.
     */
    void adopt(Instance inst, RtHalf half, int cpu, String how) {
        Contract c = inst.contract;
        inst.half = half;
        inst.cpu = cpu;
        inst.awaitingReset = c.movesHardware() && inst.everStarted;
        inst.everStarted = true;
        inst.life.to(State.ACTIVE, inst.awaitingReset ? "restarted: waits for an operator reset before motion" : null);
        RtHalf h = half;
        String who = inst.name + " (pid " + half.pid() + ")";
        half.exit().thenAccept(ex -> {
            if (!ex.requested()) { // seen now (its waiter thread, woken by the reaper); the actor handles it next
                log.accept("arflex: " + who + " exit seen: " + ex.description());
            }
            actor.submit(() -> failures.onExit(inst, h, ex));
        });
        monitor.watch(inst.name, half, c.fault().heartbeatTimeoutMs(), cfg.monotonicNs().getAsLong(),
                OutputRepair.probe(inst.name, inst.outputs));
        log.accept("arflex: " + inst.name + " ACTIVE (pid " + half.pid() + ", cpu " + cpu + ", inputs " + inst.bound
                + "; " + how + ")");
        changed.run();
    }

    private void fail(Instance inst, Exception e) {
        inst.bound.clear();
        log.accept("arflex: " + inst.name + ": start failed: " + e.getMessage());
        failures.failed(inst, true, "start failed: " + e.getMessage());
    }
}
