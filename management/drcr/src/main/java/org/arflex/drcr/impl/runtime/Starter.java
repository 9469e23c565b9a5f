package org.arflex.drcr.impl.runtime;

import java.io.IOException;
import java.util.List;
import java.util.function.Consumer;
import org.arflex.contract.Contract;
import org.arflex.drcr.impl.lifecycle.Actor;
import org.arflex.drcr.impl.lifecycle.State;
import org.arflex.drcr.impl.supervisor.HeartbeatMonitor;
import org.arflex.drcr.impl.supervisor.RtHalf;
import org.arflex.drcr.impl.supervisor.RtLauncher;
import org.arflex.planner.Wire;

/**
 * Starts the RT half of one instance (actor thread): its output segments, the spawn with the
 * control block's configuration and parameters (waiting for READY), a BIND per wire, the runtime
 * heartbeat and START; then the half is watched for hangs and its exit goes to
 * {@link Failures}. A start that fails goes to {@link Failures} as a crash would.
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

    Starter(Cell.Config cfg, Actor actor, RtLauncher launcher, HeartbeatMonitor monitor, Segments segments, Stops stops,
            Failures failures, Consumer<String> log) {
        this.cfg = cfg;
        this.actor = actor;
        this.launcher = launcher;
        this.monitor = monitor;
        this.segments = segments;
        this.stops = stops;
        this.failures = failures;
        this.log = log;
    }

    void start(Instance inst, int cpu, List<Wire> wires) {
        Contract c = inst.contract;
        RtHalf half = null;
        long t0 = cfg.monotonicNs().getAsLong();
        long tLaunched = t0;
        try {
            segments.ensure(inst);
            boolean resetRequired = c.movesHardware() && inst.everStarted;
            half = launcher.launch(new RtLauncher.Spec(cfg.runtimeId(), inst.name, inst.executable,
                    ControlSetup.config(c, cpu, cfg.noMlock()), ControlSetup.params(c, inst.params), resetRequired,
                    cfg.readyTimeoutMs()));
            tLaunched = cfg.monotonicNs().getAsLong();
            inst.bound.clear();
            for (Wire w : wires) {
                String seg = segments.name(w.provider(), w.outPort());
                half.bind(w.inPort(), seg);
                inst.bound.put(w.inPort(), seg);
            }
            half.runtimeHeartbeat(cfg.monotonicNs().getAsLong());
            half.start();
        } catch (IOException | RuntimeException e) {
            if (half != null) {
                // stopped and reaped on a stop thread; a restart of the name waits for it
                stops.submit(List.of(new Stops.Going(inst, half, List.of(), 0, "start failed")));
            }
            inst.bound.clear();
            log.accept("arflex: " + inst.name + ": start failed: " + e.getMessage());
            failures.failed(inst, true, "start failed: " + e.getMessage());
            return;
        }
        inst.half = half;
        inst.cpu = cpu;
        inst.awaitingReset = c.movesHardware() && inst.everStarted;
        inst.everStarted = true;
        inst.life.to(State.ACTIVE, inst.awaitingReset ? "restarted: waits for an operator reset before motion" : null);
        RtHalf h = half;
        half.exit().thenAccept(ex -> actor.submit(() -> failures.onExit(inst, h, ex)));
        monitor.watch(inst.name, half, c.fault().heartbeatTimeoutMs(), cfg.monotonicNs().getAsLong(),
                OutputRepair.probe(inst.name, inst.outputs));
        long t1 = cfg.monotonicNs().getAsLong();
        log.accept("arflex: " + inst.name + " ACTIVE (pid " + half.pid() + ", cpu " + cpu + ", inputs " + inst.bound
                + "; spawn to READY " + (tLaunched - t0) / 1000 + " us, bind+start " + (t1 - tLaunched) / 1000 + " us)");
    }
}
