package org.arflex.drcr.impl.runtime;

import java.io.IOException;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.LinkedHashMap;
import java.util.LinkedHashSet;
import java.util.List;
import java.util.Map;
import java.util.Optional;
import java.util.Set;
import java.util.concurrent.CompletableFuture;
import java.util.concurrent.Executor;
import java.util.concurrent.atomic.AtomicLong;
import java.util.function.Consumer;
import java.util.function.LongSupplier;
import org.arflex.contract.Contract;
import org.arflex.contract.FaultPolicy;
import org.arflex.contract.PortSpec;
import org.arflex.contract.PortType;
import org.arflex.contract.PortTypes;
import org.arflex.contract.PropertySpec;
import org.arflex.drcr.impl.abi.ControlBlock;
import org.arflex.drcr.impl.abi.PortSegment;
import org.arflex.drcr.impl.lifecycle.Actor;
import org.arflex.drcr.impl.lifecycle.State;
import org.arflex.drcr.impl.supervisor.HeartbeatMonitor;
import org.arflex.drcr.impl.supervisor.RestartPolicy;
import org.arflex.drcr.impl.supervisor.RtHalf;
import org.arflex.drcr.impl.supervisor.RtLauncher;
import org.arflex.planner.Capacities;
import org.arflex.planner.Change;
import org.arflex.planner.Plan;
import org.arflex.planner.Planner;
import org.arflex.planner.Wire;

/**
 * The running cell: instances, their RT halves and the planner that decides what runs. Every
 * method that changes something runs on the actor thread (checked); the planner is the only
 * place that decides wiring, admission and start/stop order, and the cell only executes its
 * plans, so the dry run ({@code plan}) and the real run cannot disagree.
 *
 * <p>Failure handling: an unexpected exit of an RT half (crash, kill, hang) blocks the
 * component in the planner (its dependents stop as if the provider were gone), then the restart
 * policy either schedules an unblock after the backoff or leaves it blocked as Failed.
 */
public final class Cell {

    /** Static configuration of a cell. */
    public record Config(String runtimeId, long readyTimeoutMs, long shutdownMs, boolean noMlock,
                         PortTypes types, LongSupplier monotonicNs, boolean evaluation) {

        /** A cell without the evaluation switch. */
        public Config(String runtimeId, long readyTimeoutMs, long shutdownMs, boolean noMlock, PortTypes types,
                      LongSupplier monotonicNs) {
            this(runtimeId, readyTimeoutMs, shutdownMs, noMlock, types, monotonicNs, false);
        }
    }

    /**
     * The simulator's ground-truth record (simulator/include/arflex_sim/ground_truth.h): an
     * evaluation-only state segment {@code out.truth}, type eval.GroundTruth 1.0, 192 bytes,
     * created only under {@code arflex.evaluation} for components with the attributes
     * simulated=true and role=robot; sim-robot publishes into it only if it exists.
     */
    public static final String TRUTH_PORT = "truth";
    public static final String TRUTH_TYPE = "eval.GroundTruth";
    public static final int TRUTH_SIZE = 192;

    /** True when the cell creates the ground-truth segment for this contract. */
    static boolean wantsGroundTruth(Config cfg, Contract c) {
        return cfg.evaluation() && "true".equals(c.attributes().get("simulated")) && "robot".equals(c.attributes().get("role"));
    }

    private final Config cfg;
    private final Actor actor;
    private final RtLauncher launcher;
    private final Planner planner;
    private final Consumer<String> log;
    private final HeartbeatMonitor monitor;
    private final Map<String, Instance> instances = new LinkedHashMap<>();
    private final List<String> problems = new ArrayList<>();
    private final AtomicLong generation = new AtomicLong();
    private volatile Runnable onChange = () -> { };
    private final Stops stops;
    /**
     * Components the planner wants running whose start waits until an earlier RT half of the
     * same name has exited (or until a provider they bind to has started), in start order.
     */
    private final Set<String> waiting = new LinkedHashSet<>();

    /** A cell whose stops run inline, on the caller (tests with a steppable actor). */
    public Cell(Config cfg, Actor actor, RtLauncher launcher, Planner planner, Consumer<String> log) {
        this(cfg, actor, launcher, planner, log, Runnable::run);
    }

    /**
     * @param stopper where RT halves are stopped, killed and reaped: never the actor thread in the
     *                runtime (a frozen half must not hold crash handling or the shell, issue 17)
     */
    public Cell(Config cfg, Actor actor, RtLauncher launcher, Planner planner, Consumer<String> log, Executor stopper) {
        this.cfg = cfg;
        this.actor = actor;
        this.launcher = launcher;
        this.planner = planner;
        this.log = log;
        this.monitor = new HeartbeatMonitor((half, why) -> actor.submit(() -> onHang(half, why)));
        this.stops = new Stops(actor, stopper, monitor, cfg.shutdownMs(), log, this::stopped);
    }

    /** Completes when every stop handed to the stop threads so far is recorded (any thread). */
    public CompletableFuture<Void> stopsDone() {
        return stops.idle();
    }

    /** Called after every change (on the actor thread): service registrations follow it. */
    public void onChange(Runnable r) {
        onChange = r;
    }

    public Config config() {
        return cfg;
    }

    public Actor actor() {
        return actor;
    }

    public Planner planner() {
        return planner;
    }

    public HeartbeatMonitor monitor() {
        return monitor;
    }

    long generation() {
        return generation.get();
    }

    /** Records a problem (bad contract...) for the DTO and the log. */
    public void problem(String p) {
        log.accept("arflex: " + p);
        synchronized (problems) {
            problems.add(p);
            if (problems.size() > 100) {
                problems.remove(0);
            }
        }
        changed();
    }

    List<String> problems() {
        synchronized (problems) {
            return List.copyOf(problems);
        }
    }

    /** Instances in install order (actor thread, or for snapshots). */
    List<Instance> instances() {
        return List.copyOf(instances.values());
    }

    public Optional<Instance> instance(String name) {
        return Optional.ofNullable(instances.get(name));
    }

    /** Names of the instances. */
    public List<String> names() {
        return List.copyOf(instances.keySet());
    }

    private void changed() {
        generation.incrementAndGet();
        try {
            onChange.run();
        } catch (RuntimeException e) {
            log.accept("arflex: change listener failed: " + e);
        }
    }

    // ---- install / uninstall ---------------------------------------------------------------

    /**
     * Registers the contract of an installed bundle that is not started: the instance shows as
     * INSTALLED and is not planned. A name already used by another bundle is refused with a
     * problem.
     *
     * @return false when refused
     */
    public boolean register(Contract c, long bundleId) {
        actor.checkThread();
        Instance existing = instances.get(c.name());
        if (existing != null) {
            if (existing.bundleId != bundleId) {
                problem(c.source() + ": component '" + c.name() + "' is already installed by bundle " + existing.bundleId
                        + "; the contract of bundle " + bundleId + " is skipped");
                return false;
            }
            if (!existing.planned) {
                existing.params = Instance.carried(existing.contract, existing.params, c);
                existing.contract = c;
                existing.policy = new RestartPolicy(c.fault(), actor.clock());
                changed();
            }
            return true;
        }
        if (!validName(c, bundleId)) {
            return false;
        }
        Instance inst = new Instance(c, bundleId, null, actor, log);
        inst.life.target(State.INSTALLED);
        inst.life.reason("bundle " + bundleId + " is not started");
        instances.put(c.name(), inst);
        changed();
        return true;
    }

    /** Forgets an INSTALLED (not started) instance of that bundle; its bundle was uninstalled or updated. */
    public void unregister(String name, long bundleId) {
        actor.checkThread();
        Instance inst = instances.get(name);
        if (inst != null && inst.bundleId == bundleId && !inst.planned) {
            inst.life.to(State.DESTROYED, "bundle " + bundleId + " uninstalled");
            instances.remove(name);
            changed();
        }
    }

    private boolean validName(Contract c, long bundleId) {
        if (c.name().length() > 40) {
            problem(c.source() + ": component name '" + c.name() + "' is longer than 40 characters, the limit of "
                    + "shared object names (rt-core ABI); skipped");
            return false;
        }
        return true;
    }

    /**
     * Installs a component whose bundle started (or, when it is planned already, replaces its
     * contract). A name already used by another bundle is refused with a problem; nothing else
     * changes.
     *
     * @return false when refused
     */
    public boolean install(Contract c, long bundleId, Path exe) {
        actor.checkThread();
        Instance existing = instances.get(c.name());
        if (existing != null && existing.bundleId != bundleId) {
            problem(c.source() + ": component '" + c.name() + "' is already installed by bundle " + existing.bundleId
                    + "; the contract of bundle " + bundleId + " is skipped");
            return false;
        }
        if (existing == null && !validName(c, bundleId)) {
            return false;
        }
        boolean replace = existing != null && existing.planned;
        Plan plan;
        try {
            plan = planner.apply(replace ? Change.replace(c) : Change.install(c));
        } catch (RuntimeException e) {
            problem(c.source() + ": planner refused '" + c.name() + "': " + e.getMessage());
            return false;
        }
        Instance inst = existing;
        if (inst == null) {
            inst = new Instance(c, bundleId, exe, actor, log);
            instances.put(c.name(), inst);
        } else {
            inst.params = Instance.carried(inst.contract, inst.params, c);
            inst.contract = c;
            inst.executable = exe;
            inst.policy = new RestartPolicy(c.fault(), actor.clock());
            if (replace) {
                // the new contract's outputs replace the old ones once the old producer is gone
                inst.outputsStale = true;
            }
        }
        inst.planned = true;
        inst.life.target(State.ACTIVE);
        inst.life.to(State.UNSATISFIED, "resolving");
        log.accept("arflex: " + plan.title() + "\n" + plan.toText());
        execute(plan);
        changed();
        return true;
    }

    /** Removes a component for good: stops it (and what depends on it), removes its objects. */
    public CompletableFuture<Void> uninstall(String name, String why) {
        return uninstall(List.of(name), why);
    }

    /**
     * Removes components for good (a bundle's, or all of them) in one plan: what depends on
     * them stops or is rewired once, and their own halves stop side by side (as a plan's stops
     * do), then their objects are removed. The halves stop on a stop thread: an instance whose
     * half is still on its way out becomes DESTROYED, and its output segments go, when the half
     * is gone.
     *
     * @return completes when the stops settled: every half exited, or one did not answer and is
     *         being terminated (a caller may wait for it, off the actor)
     */
    public CompletableFuture<Void> uninstall(List<String> names, String why) {
        actor.checkThread();
        List<Instance> going = new ArrayList<>();
        for (String name : names) {
            Instance inst = instances.get(name);
            if (inst != null) {
                inst.life.target(State.DESTROYED);
                cancelRestart(inst);
                going.add(inst);
            }
        }
        if (going.isEmpty()) {
            return CompletableFuture.completedFuture(null);
        }
        String[] planned = going.stream().filter(i -> i.planned).map(i -> i.name).toArray(String[]::new);
        if (planned.length > 0) {
            try {
                execute(planner.apply(Change.uninstall(planned)));
            } catch (RuntimeException e) {
                log.accept("arflex: planner failed on uninstall of " + String.join(", ", planned) + ": " + e);
            }
        }
        List<Stops.Going> rest = new ArrayList<>();
        for (Instance inst : going) {
            Stops.Going g = detach(inst, why);
            if (g != null) {
                rest.add(g);
            }
        }
        stops.submit(rest);
        for (Instance inst : going) {
            instances.remove(inst.name);
            waiting.remove(inst.name);
            inst.destroyReason = why;
            if (!stops.stopping(inst)) {
                closeOutputs(inst);
                inst.life.to(State.DESTROYED, why);
            }
        }
        changed();
        return stops.settled(going);
    }

    /**
     * Uninstalls everything (DRCR stop). The halves stop on stop threads: wait for
     * {@link #stopsDone()} (off the actor) before the actor ends, so that no process and no
     * shared object is left behind.
     */
    public void shutdownAll(String why) {
        actor.checkThread();
        List<String> names = new ArrayList<>(instances.keySet());
        java.util.Collections.reverse(names);
        uninstall(names, why);
    }

    /** Names of the components that bundle {@code bundleId} installed. */
    public List<String> namesOfBundle(long bundleId) {
        List<String> out = new ArrayList<>();
        for (Instance i : instances.values()) {
            if (i.bundleId == bundleId) {
                out.add(i.name);
            }
        }
        return out;
    }

    // ---- plans -------------------------------------------------------------------------------

    /** Applies a change (capacities, measured WCET...) and executes the plan. */
    public Plan apply(Change change) {
        actor.checkThread();
        Plan p = planner.apply(change);
        if (!p.isEmpty()) {
            log.accept("arflex: " + p.title() + "\n" + p.toText());
        }
        execute(p);
        changed();
        return p;
    }

    /** A dry run. */
    public Plan dryRun(Change change) {
        actor.checkThread();
        return planner.plan(change);
    }

    private void execute(Plan plan) {
        // Live rewiring: inputs whose provider changes or goes are unbound before any stop, so
        // no consumer reads a provider while it goes away; new bindings come after the starts,
        // when every provider's segment exists.
        for (Plan.Action a : plan.rewires()) {
            rebind(instances.get(a.component()), plan.wiringOf(a.component()), false, a.reason());
        }
        // The plan's stops in three sweeps, so that their waits overlap: every half to stop is
        // detached and its inputs unbound, then each is given its cycles to run its safe
        // behaviour (counted from the unbind, so the waits run side by side), then each is
        // stopped and shut down in the plan's stop order.
        // They run on a stop thread (Stops), so the actor is free for crashes and the shell
        // while a half that does not answer is terminated.
        List<Stops.Going> going = new ArrayList<>();
        for (String name : plan.stopOrder()) {
            Instance inst = instances.get(name);
            Stops.Going g = inst == null ? null : detach(inst, plan.inactiveAfter().getOrDefault(name,
                    plan.action(name).map(Plan.Action::reason).orElse("stopped by plan")));
            if (g != null) {
                going.add(g);
            }
        }
        stops.submit(going);
        // A component whose previous half is still on its way out starts when it is gone (its
        // objects have the same names), and so does one bound to such a component.
        Set<String> later = new LinkedHashSet<>();
        for (String name : plan.startOrder()) {
            Instance inst = instances.get(name);
            if (inst != null && inst.half == null && (stops.pending(name) || waiting.contains(name)
                    || plan.wiringOf(name).stream().anyMatch(w -> later.contains(w.provider())))) {
                later.add(name);
            }
        }
        for (String name : later) {
            waitFor(instances.get(name));
        }
        // Every output segment of every component about to start exists before the first one
        // starts: a member of a start group (a cycle) binds to its partners' outputs at once.
        // A failure here is reported by that component's own start below.
        for (String name : plan.startOrder()) {
            Instance inst = instances.get(name);
            if (inst != null && inst.half == null && !later.contains(name)) {
                try {
                    ensureOutputs(inst);
                } catch (IOException | RuntimeException e) {
                    // startHalf tries again and fails the component with this reason.
                }
            }
        }
        for (String name : plan.startOrder()) {
            Instance inst = instances.get(name);
            // A start that failed earlier in this loop blocked its component, and the nested
            // plan took its dependents out of the active set: ask the planner again.
            if (inst != null && inst.half == null && inst.life.state() != State.FAILED
                    && planner.active().contains(name) && !later.contains(name)) {
                startHalf(inst, plan.cpuAssignment().getOrDefault(name, -1), plan.wiringOf(name));
            }
        }
        for (Plan.Action a : plan.rewires()) {
            rebind(instances.get(a.component()), plan.wiringOf(a.component()).stream()
                    .filter(w -> !waiting.contains(w.provider())).toList(), true, a.reason());
        }
        // Everything the plan leaves inactive shows the planner's reason (a start that waited is
        // off when the planner no longer wants it).
        Set<String> activeNow = planner.active();
        waiting.removeIf(n -> !activeNow.contains(n));
        for (var e : plan.inactiveAfter().entrySet()) {
            Instance inst = instances.get(e.getKey());
            if (inst != null && inst.half == null && inst.life.state() != State.FAILED
                    && inst.life.state() != State.DESTROYED && !waiting.contains(inst.name)) {
                if (inst.restartTimer == null || inst.life.reason() == null) {
                    inst.life.to(State.UNSATISFIED, e.getValue());
                }
            }
        }
    }

    /**
     * One phase of a REBIND: unbind (bindPhase false) the inputs whose segment changes or goes,
     * or bind (bindPhase true) the inputs to their new segments. The RT half picks a binding up
     * at a cycle boundary and keeps running. A refused command means the half cannot follow
     * the new wiring: it is restarted through the normal failure path, as a crash would be.
     */
    private void rebind(Instance inst, List<Wire> wires, boolean bindPhase, String why) {
        if (inst == null || inst.half == null) {
            return;
        }
        Map<String, String> target = new java.util.TreeMap<>();
        for (Wire w : wires) {
            target.put(w.inPort(), segmentOf(w.provider(), w.outPort()));
        }
        try {
            if (!bindPhase) {
                for (String port : List.copyOf(inst.bound.keySet())) {
                    if (!inst.bound.get(port).equals(target.get(port))) {
                        inst.half.unbind(port);
                        inst.bound.remove(port);
                    }
                }
                return;
            }
            for (var e : target.entrySet()) {
                if (!e.getValue().equals(inst.bound.get(e.getKey()))) {
                    inst.half.bind(e.getKey(), e.getValue());
                    inst.bound.put(e.getKey(), e.getValue());
                }
            }
            log.accept("arflex: " + inst.name + " rewired while running (" + why + "); inputs " + inst.bound);
        } catch (IOException | RuntimeException e) {
            log.accept("arflex: " + inst.name + ": rewiring failed: " + e.getMessage() + "; restarting it");
            RtHalf h = inst.half;
            h.kill();
        }
    }

    // ---- RT halves -----------------------------------------------------------------------------

    private String segmentOf(String provider, String port) {
        return "/arflex." + cfg.runtimeId() + "." + provider + ".out." + port;
    }

    private void ensureOutputs(Instance inst) throws IOException {
        if (inst.outputsStale && !stops.stopping(inst)) {
            closeOutputs(inst); // a replaced contract's segments, their producer gone
            inst.outputsStale = false;
        }
        for (PortSpec p : inst.contract.outputs()) {
            if (inst.outputs.containsKey(p.name())) {
                continue;
            }
            PortType t = cfg.types().find(p.type()).orElseThrow(() -> new IOException(
                    "output " + p.name() + ": port type " + p.type() + " is not known to this runtime"));
            int elem = (int) (t.size() + t.maxPayload());
            int method = switch (p.method()) {
                case STATE -> PortSegment.METHOD_STATE;
                case STREAM -> PortSegment.METHOD_STREAM;
                case FRAME -> PortSegment.METHOD_FRAME;
            };
            int overflow = p.overflow() == PortSpec.Overflow.DROP_NEWEST ? PortSegment.OVERFLOW_DROP_NEWEST
                    : PortSegment.OVERFLOW_DROP_OLDEST;
            inst.outputs.put(p.name(), launcher.createOutput(segmentOf(inst.name, p.name()), method, t.name(),
                    t.version().major(), t.version().minor(), elem, Math.max(1, p.depth()), overflow));
        }
        if (wantsGroundTruth(cfg, inst.contract) && !inst.evaluationOutputs.containsKey(TRUTH_PORT)) {
            // Never a contract port: no wire, no BIND names it; evaluation tools map it read-only.
            RtLauncher.Output o = launcher.createOutput(segmentOf(inst.name, TRUTH_PORT), PortSegment.METHOD_STATE,
                    TRUTH_TYPE, 1, 0, TRUTH_SIZE, 1, PortSegment.OVERFLOW_NONE);
            inst.evaluationOutputs.put(TRUTH_PORT, o);
            inst.evaluationSegments = Map.of(TRUTH_PORT, o.name());
        }
    }

    private void closeOutputs(Instance inst) {
        for (RtLauncher.Output o : inst.outputs.values()) {
            o.close();
        }
        inst.outputs.clear();
        for (RtLauncher.Output o : inst.evaluationOutputs.values()) {
            o.close();
        }
        inst.evaluationOutputs.clear();
        inst.evaluationSegments = Map.of();
    }

    /**
     * The control block's configuration of an instance. A service (best effort, SCHED_OTHER, no
     * deadline) does not lock its memory: locking buys it nothing, and locking and unlocking a
     * large process (a MuJoCo/OSMesa camera, 256 MiB) at its start and exit stalled the 1 ms
     * components of the cell for several periods each time (./arflex bench cell, docs/DECISIONS.md D8).
     */
    static ControlBlock.Config controlConfig(Contract c, int cpu, boolean noMlock) {
        boolean service = c.taskType() == Contract.TaskType.SERVICE;
        int flags = (c.movesHardware() ? ControlBlock.CFG_MOVES_HARDWARE : 0)
                | (noMlock || service ? ControlBlock.CFG_NO_MLOCK : 0);
        int taskType = switch (c.taskType()) {
            case PERIODIC -> 0;
            case SPORADIC -> 1;
            case SERVICE -> 2;
        };
        return new ControlBlock.Config(c.timing().periodNs(), c.timing().deadlineNs(),
                c.fault().heartbeatTimeoutMs() * 1_000_000L, cpu >= 0 ? 1L << cpu : 0L,
                c.taskType() == Contract.TaskType.SERVICE ? 0 : c.timing().priority(), taskType,
                c.fault().safeOutput() == FaultPolicy.SafeOutput.ZERO ? 1 : 0, flags,
                c.fault().orphanHoldMs() * 1_000_000L);
    }

    static List<ControlBlock.Param> controlParams(Contract c, long[] values) {
        List<ControlBlock.Param> out = new ArrayList<>();
        for (int i = 0; i < c.properties().size(); i++) {
            PropertySpec p = c.properties().get(i);
            int type = switch (p.type()) {
                case BOOL -> ControlBlock.PARAM_BOOL;
                case INT -> ControlBlock.PARAM_INT64;
                case DOUBLE -> ControlBlock.PARAM_DOUBLE;
            };
            long min = bound(p, p.min(), true);
            long max = bound(p, p.max(), false);
            out.add(new ControlBlock.Param(p.name(), type, p.mutable(), min, max, values[i]));
        }
        return out;
    }

    private static long bound(PropertySpec p, Optional<Double> b, boolean lower) {
        return switch (p.type()) {
            case BOOL -> lower ? 0 : 1;
            case INT -> b.map(Double::longValue).orElse(lower ? Long.MIN_VALUE : Long.MAX_VALUE);
            case DOUBLE -> Double.doubleToRawLongBits(b.orElse(lower ? -Double.MAX_VALUE : Double.MAX_VALUE));
        };
    }

    private void startHalf(Instance inst, int cpu, List<Wire> wires) {
        Contract c = inst.contract;
        RtHalf half = null;
        long t0 = cfg.monotonicNs().getAsLong();
        long tLaunched = t0;
        try {
            ensureOutputs(inst);
            boolean resetRequired = c.movesHardware() && inst.everStarted;
            half = launcher.launch(new RtLauncher.Spec(cfg.runtimeId(), inst.name, inst.executable,
                    controlConfig(c, cpu, cfg.noMlock()), controlParams(c, inst.params), resetRequired,
                    cfg.readyTimeoutMs()));
            tLaunched = cfg.monotonicNs().getAsLong();
            inst.bound.clear();
            for (Wire w : wires) {
                String seg = segmentOf(w.provider(), w.outPort());
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
            failed(inst, true, "start failed: " + e.getMessage());
            return;
        }
        inst.half = half;
        inst.cpu = cpu;
        inst.awaitingReset = c.movesHardware() && inst.everStarted;
        inst.everStarted = true;
        inst.life.to(State.ACTIVE, inst.awaitingReset ? "restarted: waits for an operator reset before motion" : null);
        RtHalf h = half;
        half.exit().thenAccept(ex -> actor.submit(() -> onExit(inst, h, ex)));
        monitor.watch(inst.name, half, c.fault().heartbeatTimeoutMs(), cfg.monotonicNs().getAsLong(),
                OutputRepair.probe(inst.name, inst.outputs));
        long t1 = cfg.monotonicNs().getAsLong();
        log.accept("arflex: " + inst.name + " ACTIVE (pid " + half.pid() + ", cpu " + cpu + ", inputs " + inst.bound
                + "; spawn to READY " + (tLaunched - t0) / 1000 + " us, bind+start " + (t1 - tLaunched) / 1000 + " us)");
    }

    /**
     * First step of a stop, on the actor: the half is detached (its exit is expected from here
     * and ignored by onExit, a hang by onHang) and the instance is no longer Active. The rest
     * (UNBIND, the wait for its safe behaviour, STOP, SHUTDOWN, the signals) runs on a stop
     * thread ({@link Stops}). The half stays watched until then, so the runtime heartbeat goes
     * on while it settles: a slow component (cameras at 500 ms) must not see the runtime lost
     * and latch safe mode on its way out. Returns null when nothing runs.
     */
    private Stops.Going detach(Instance inst, String why) {
        RtHalf half = inst.half;
        if (half == null) {
            return null;
        }
        inst.half = null;
        List<String> inputs = List.copyOf(inst.bound.keySet());
        inst.bound.clear();
        inst.cpu = -1;
        if (inst.life.state() == State.ACTIVE) {
            inst.life.to(State.UNSATISFIED, why);
        }
        long periods = 3 * inst.contract.timing().periodNs() / 1_000_000L;
        return new Stops.Going(inst, half, inputs, Math.max(100, periods), why);
    }

    /**
     * Records a batch of stops (actor thread): the log line with how each half ended, the reason
     * of an instance whose half had to be killed, the output segments of uninstalled instances
     * (closed only now that their producer is gone), and the starts that waited for a name.
     */
    private void stopped(Stops.Batch b) {
        for (Stops.Going g : b.halves) {
            Instance inst = g.inst;
            log.accept("arflex: " + inst.name + " (pid " + g.half.pid() + ") stopped: " + g.why + " (" + g.outcome + ")");
            boolean destroyed = inst.life.target() == State.DESTROYED && instances.get(inst.name) != inst;
            String why = g.forced() ? g.why + "; RT half " + g.outcome : g.why;
            if (destroyed) {
                closeOutputs(inst);
                String base = inst.destroyReason != null ? inst.destroyReason : g.why;
                inst.life.to(State.DESTROYED, g.forced() ? base + "; RT half " + g.outcome : base);
            } else if (inst.half == null && g.forced() && g.why.equals(inst.life.reason())) {
                inst.life.reason(why);
            }
        }
        resume();
        changed();
    }

    /** Marks a component as starting once its name is free (actor thread). */
    private void waitFor(Instance inst) {
        if (waiting.add(inst.name) && inst.life.state() != State.FAILED) {
            inst.life.to(State.UNSATISFIED, "starts when its previous RT half has exited");
            log.accept("arflex: " + inst.name + ": start waits for its previous RT half to exit");
        }
    }

    /**
     * Starts what waited for a name that is free now, with the planner's current CPU and
     * wiring, providers first; then binds running consumers to providers that started here.
     */
    private void resume() {
        if (waiting.isEmpty()) {
            return;
        }
        Plan now = planner.current();
        List<String> ready = new ArrayList<>();
        Set<String> still = new LinkedHashSet<>();
        for (String name : List.copyOf(waiting)) {
            Instance inst = instances.get(name);
            if (inst == null || inst.half != null || inst.life.state() == State.FAILED || !planner.active().contains(name)) {
                waiting.remove(name);
                continue;
            }
            if (stops.pending(name) || now.wiringOf(name).stream().anyMatch(w -> still.contains(w.provider()))) {
                still.add(name);
            } else {
                ready.add(name);
            }
        }
        if (ready.isEmpty()) {
            return;
        }
        waiting.removeAll(ready);
        for (String name : ready) {
            Instance inst = instances.get(name);
            try {
                ensureOutputs(inst);
            } catch (IOException | RuntimeException e) {
                // startHalf tries again and fails the component with this reason
            }
        }
        for (String name : ready) {
            Instance inst = instances.get(name);
            if (inst.half == null && inst.life.state() != State.FAILED && planner.active().contains(name)) {
                log.accept("arflex: " + name + ": its previous RT half has exited; starting");
                startHalf(inst, now.cpuAssignment().getOrDefault(name, -1), now.wiringOf(name));
            }
        }
        for (Instance inst : List.copyOf(instances.values())) {
            if (inst.half == null) {
                continue;
            }
            List<Wire> wires = now.wiringOf(inst.name).stream().filter(w -> !waiting.contains(w.provider())).toList();
            if (wires.stream().anyMatch(w -> !segmentOf(w.provider(), w.outPort()).equals(inst.bound.get(w.inPort())))) {
                rebind(inst, wires, true, "its provider started after its previous RT half exited");
            }
        }
    }

    private void onHang(RtHalf half, String why) {
        for (Instance inst : instances.values()) {
            if (inst.half == half) {
                log.accept("arflex: " + inst.name + ": " + why + "; killing pid " + half.pid());
                inst.hangReason = why;
                half.kill();
            }
        }
    }

    private void onExit(Instance inst, RtHalf half, RtHalf.Exit exit) {
        actor.checkThread();
        if (inst.half != half) {
            return; // an orderly stop, already handled
        }
        inst.half = null;
        monitor.unwatch(half);
        half.cleanup();
        inst.bound.clear();
        inst.cpu = -1;
        String what = inst.hangReason != null ? inst.hangReason : exit.description();
        inst.hangReason = null;
        log.accept("arflex: " + inst.name + " (pid " + half.pid() + ") " + what);
        OutputRepair.dropDamaged(inst.name, inst.outputs, log);
        failed(inst, exit.abnormal(), "RT half " + what);
        changed();
    }

    /** The restart policy decides after a crash, hang or failed start. */
    private void failed(Instance inst, boolean abnormal, String what) {
        RestartPolicy.Decision d = inst.policy.onExit(abnormal, what);
        if (d.restart()) {
            inst.restarts++;
            String why = "restarting in " + d.delayMs() + " ms (" + d.reason() + ")";
            inst.life.to(State.UNSATISFIED, why);
            execute(planner.apply(Change.block(inst.name, why)));
            inst.life.reason(why);
            cancelRestart(inst);
            inst.restartTimer = actor.schedule(() -> {
                inst.restartTimer = null;
                if (instances.get(inst.name) == inst && inst.life.state() != State.FAILED) {
                    inst.life.reason("restarting");
                    execute(planner.apply(Change.unblock(inst.name)));
                    changed();
                }
            }, d.delayMs());
        } else {
            inst.life.to(State.FAILED, d.reason());
            execute(planner.apply(Change.block(inst.name, "failed: " + d.reason())));
        }
    }

    private void cancelRestart(Instance inst) {
        if (inst.restartTimer != null) {
            inst.restartTimer.cancel();
            inst.restartTimer = null;
        }
    }

    // ---- management ------------------------------------------------------------------------------

    /**
     * Operator reset: a Failed instance gets a new chance; a running one that moves hardware is
     * allowed to drive outputs again (RESET command).
     */
    public String reset(String name) {
        actor.checkThread();
        Instance inst = require(name);
        if (inst.life.state() == State.FAILED) {
            List<String> repaired = OutputRepair.dropDamaged(name, inst.outputs, log);
            inst.policy.reset();
            inst.life.to(State.UNSATISFIED, "reset by operator");
            execute(planner.apply(Change.unblock(name)));
            changed();
            return name + ": reset from FAILED, now " + inst.life.state() + (repaired.isEmpty() ? ""
                    : "; " + String.join("; ", repaired));
        }
        RtHalf half = inst.half;
        if (half == null) {
            return name + ": nothing to reset (" + inst.life.state() + ")";
        }
        try {
            half.reset();
        } catch (IOException e) {
            String why = Holding.reason(this, inst, half.flags(), half.hold(), true);
            throw new IllegalStateException(name + ": reset refused, the cause persists: "
                    + (why != null ? why : e.getMessage()) + " (" + e.getMessage() + ")");
        }
        inst.awaitingReset = false;
        if (inst.life.state() == State.ACTIVE) {
            inst.life.reason(null);
        }
        changed();
        return name + ": reset sent, outputs enabled";
    }

    /**
     * Sets a parameter with type, range and mutability checks; returns the applied value.
     *
     * @throws IllegalArgumentException naming the parameter and what is wrong
     */
    public String setParam(String name, String param, String text) {
        actor.checkThread();
        Instance inst = require(name);
        Contract c = inst.contract;
        int idx = -1;
        for (int i = 0; i < c.properties().size(); i++) {
            if (c.properties().get(i).name().equals(param)) {
                idx = i;
            }
        }
        if (idx < 0) {
            throw new IllegalArgumentException(name + ": no parameter '" + param + "' (has "
                    + c.properties().stream().map(PropertySpec::name).toList() + ")");
        }
        PropertySpec p = c.properties().get(idx);
        long bits = Params.parse(p, text);
        RtHalf half = inst.half;
        if (half != null && !p.mutable()) {
            throw new IllegalArgumentException(name + "." + param + " is immutable while " + inst.life.state()
                    + " (mutable=false)");
        }
        long applied = bits;
        if (half != null) {
            try {
                applied = half.setParam(idx, bits);
            } catch (IOException e) {
                throw new IllegalStateException(name + "." + param + ": " + e.getMessage());
            }
            applied = half.paramValue(idx);
        }
        long[] v = inst.params.clone();
        v[idx] = applied;
        inst.params = v;
        changed();
        return Params.format(p, applied);
    }

    /** Reads a parameter as applied (control block when running, configuration otherwise). */
    public String getParam(String name, String param) {
        Instance inst = require(name);
        List<PropertySpec> props = inst.contract.properties();
        for (int i = 0; i < props.size(); i++) {
            if (props.get(i).name().equals(param)) {
                RtHalf half = inst.half;
                long bits = half != null ? half.paramValue(i) : inst.params[i];
                return Params.format(props.get(i), bits);
            }
        }
        throw new IllegalArgumentException(name + ": no parameter '" + param + "'");
    }

    /** Records a measured execution time above the declared WCET and re-plans with it. */
    public void measuredWcet(String name, long ns) {
        actor.checkThread();
        Instance inst = instances.get(name);
        if (inst == null || ns <= inst.contract.timing().wcetNs() || ns <= inst.measuredWcetNs) {
            return;
        }
        inst.measuredWcetNs = ns;
        log.accept("arflex: " + name + ": measured execution time " + ns + " ns above declared WCET "
                + inst.contract.timing().wcetNs() + " ns; re-planning");
        apply(Change.measuredWcet(name, ns));
    }

    /**
     * Periodic sampling on the actor thread: the execution time of each running RT half against
     * its declared WCET. Only a sustained exceedance is recorded as the measured WCET and
     * re-planned with ({@link #sustainedOverWcet}); an isolated one (a preemption or a stall of
     * the machine, which a wall-clock execution time includes) is logged once and kept out of
     * admission, so one spike cannot stop a component for good.
     *
     * @return total cycles whose execution time exceeded the declared WCET
     */
    public long sample() {
        actor.checkThread();
        long over = 0;
        for (Instance inst : List.copyOf(instances.values())) {
            RtHalf h = inst.half;
            if (h == null) {
                continue;
            }
            long wcet = inst.contract.timing().wcetNs();
            ControlBlock.Stats s = h.stats(wcet);
            if (s == null) {
                continue;
            }
            over += s.execOverWcet();
            if (s.execCount() < inst.sampledExecCount) {  // a new RT half counts from zero
                inst.sampledExecCount = inst.sampledExecSum = inst.sampledExecOver = 0;
            }
            long dCount = s.execCount() - inst.sampledExecCount;
            long dSum = s.execSumNs() - inst.sampledExecSum;
            long dOver = s.execOverWcet() - inst.sampledExecOver;
            inst.sampledExecCount = s.execCount();
            inst.sampledExecSum = s.execSumNs();
            inst.sampledExecOver = s.execOverWcet();
            if (dCount <= 0 || s.execMaxNs() <= wcet) {
                continue;
            }
            if (sustainedOverWcet(wcet, dCount, dSum, dOver)) {
                measuredWcet(inst.name, s.execMaxNs());
            } else if (dOver > 0 && !inst.transientWcetLogged) {
                inst.transientWcetLogged = true;
                log.accept("arflex: " + inst.name + ": execution time up to " + s.execMaxNs() + " ns above declared WCET "
                        + wcet + " ns in isolated cycles (" + dOver + " of " + dCount + "); not re-planned (logged once)");
            }
        }
        return over;
    }

    /** Cycles of a sampling window above the declared WCET that make an exceedance sustained. */
    static final double SUSTAINED_FRACTION = 0.01;
    static final long SUSTAINED_MIN_CYCLES = 3;

    /**
     * Whether one sampling window shows a sustained WCET exceedance: at least 1 % of its cycles
     * (and at least 3) above the declared WCET, or a mean execution time above it. Above the
     * execution-time histogram's range (200 us) the histogram only counts cycles of 200 us or
     * more, an upper bound, so there only the mean decides.
     */
    static boolean sustainedOverWcet(long wcetNs, long cycles, long sumNs, long over) {
        if (cycles <= 0) {
            return false;
        }
        if (sumNs / cycles > wcetNs) {
            return true;
        }
        long histRangeNs = (long) ControlBlock.HIST_BINS * ControlBlock.HIST_BIN_NS;
        return wcetNs < histRangeNs
                && over >= Math.max(SUSTAINED_MIN_CYCLES, (long) Math.ceil(cycles * SUSTAINED_FRACTION));
    }

    /** New capacities: re-plan (the lowest criticality goes first). */
    public Plan capacities(Capacities c) {
        return apply(Change.capacities(c));
    }

    Instance require(String name) {
        Instance inst = instances.get(name);
        if (inst == null) {
            throw new IllegalArgumentException("no component '" + name + "' (installed: " + instances.keySet() + ")");
        }
        return inst;
    }
}
