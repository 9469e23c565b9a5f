package org.arflex.drcr.impl.runtime;

import java.nio.file.Path;
import java.util.ArrayList;
import java.util.Collections;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import java.util.Optional;
import java.util.concurrent.CompletableFuture;
import java.util.concurrent.Executor;
import java.util.concurrent.atomic.AtomicLong;
import java.util.function.Consumer;
import java.util.function.LongSupplier;
import org.arflex.contract.Contract;
import org.arflex.contract.PortTypes;
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

/**
 * The running cell: the registry of instances and the façade that services, shell and extender
 * use. Every method that changes something runs on the actor thread (checked); the planner is
 * the only place that decides wiring, admission and start/stop order, and the cell only executes
 * its plans, so the dry run ({@code plan}) and the real run cannot disagree.
 *
 * <p>One class per job, wired here: {@link PlanExecutor} executes plans and {@link Starter}
 * starts an RT half (actor thread); {@link Stops} stops halves (stop threads); {@link Segments}
 * and {@link EvaluationSegments} own the output segments; {@link Failures} handles crashes,
 * hangs, restarts with backoff and the operator reset; {@link Parameters} reads and sets
 * parameters; {@link WcetMonitor} samples execution times against the declared WCET.
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

    private final Config cfg;
    private final Actor actor;
    private final Planner planner;
    private final Consumer<String> log;
    private final HeartbeatMonitor monitor;
    private final Map<String, Instance> instances = new LinkedHashMap<>();
    private final List<String> problems = new ArrayList<>();
    private final AtomicLong generation = new AtomicLong();
    private volatile Runnable onChange = () -> { };
    private final Stops stops;
    private final Segments segments;
    private final Failures failures;
    private final Starter starter;
    private final PlanExecutor plans;
    private final WcetMonitor wcet;
    private final ChangeSetExecutor changeSets;
    /** The live progress of the change set being applied (D53); read from any thread. */
    private final ChangeSetProgress changeSetProgress = new ChangeSetProgress(System::currentTimeMillis);

    /** A cell whose launches and stops run inline, on the caller (tests with a steppable actor). */
    public Cell(Config cfg, Actor actor, RtLauncher launcher, Planner planner, Consumer<String> log) {
        this(cfg, actor, launcher, planner, log, Runnable::run, Runnable::run);
    }

    /**
     * @param stopper  where RT halves are stopped, killed and reaped: never the actor thread in the
     *                 runtime (a frozen half must not hold crash handling or the shell, issue 17)
     * @param launches where RT halves are spawned and awaited until READY: never the actor thread
     *                 in the runtime, for the same reason
     */
    public Cell(Config cfg, Actor actor, RtLauncher launcher, Planner planner, Consumer<String> log, Executor stopper,
                Executor launches) {
        this.cfg = cfg;
        this.actor = actor;
        this.planner = planner;
        this.log = log;
        this.monitor = new HeartbeatMonitor((half, why) -> actor.submit(() -> hung(half, why)));
        this.stops = new Stops(actor, stopper, monitor, cfg.shutdownMs(), log, this::stopped);
        this.segments = new Segments(cfg.runtimeId(), cfg.types(), launcher, stops,
                new EvaluationSegments(cfg.evaluation(), launcher), this::objectId);
        this.failures = new Failures(this, this::execute, log, this::exitedInWindow);
        this.starter = new Starter(cfg, actor, launcher, monitor, segments, stops, failures, log, launches,
                planner, this::changed, this::resume);
        this.plans = new PlanExecutor(this, stops, segments, starter, log);
        this.wcet = new WcetMonitor(this, log);
        this.changeSets = new ChangeSetExecutor(this, stops, segments, starter, plans, failures, log, changeSetProgress);
    }

    // Callbacks into parts built after the part that calls them (a crash re-plans, a plan's
    // start may fail, a plan's stops are recorded): they only run once the cell is built.

    private void execute(Plan plan) {
        plans.execute(plan);
    }

    private boolean exitedInWindow(Instance inst, RtHalf half, RtHalf.Exit ex) {
        return changeSets.exited(inst, half, ex);
    }

    private void hung(RtHalf half, String why) {
        failures.onHang(half, why);
    }

    private void stopped(Stops.Batch b) {
        plans.stopped(b);
    }

    private void resume() {
        plans.resume();
        changed();
    }

    /**
     * Completes when every launch begun so far and every stop handed to the stop threads so far
     * (also the stops of launches nobody wanted any more) is recorded (any thread).
     */
    public CompletableFuture<Void> stopsDone() {
        return starter.idle().thenCompose(v -> stops.idle());
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

    /** The lifecycle state of the instance of that name (INSTALLED ... FAILED), or null (actor thread). */
    public String state(String name) {
        Instance i = instances.get(name);
        return i == null ? null : i.life.state().name();
    }

    /** The instance of that name, or null (actor thread). */
    Instance find(String name) {
        return instances.get(name);
    }

    /**
     * The object id the current RT half of component {@code name} runs under: its name, or the
     * generation id an update in a change set gave it (D38); the name itself when unknown.
     */
    String objectId(String name) {
        Instance i = instances.get(name);
        return i == null ? name : i.objectId;
    }

    /** Names of the instances. */
    public List<String> names() {
        return List.copyOf(instances.keySet());
    }

    /** Counts a change and tells the listener (actor thread). */
    void changed() {
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
        if (existing != null && existing.planned && existing.life.target() == State.ACTIVE
                && ContractReader.sameButSource(existing.contract, c)) {
            // The bundle of a component a change set installed is started after the switch (D35),
            // or a committed update's bundle was updated to that version (D43): the component
            // runs already with this contract; only the extracted copy is new.
            existing.executable = exe;
            log.accept("arflex: " + c.name() + ": bundle " + bundleId + " started; the component "
                    + (existing.contract == c ? "was installed by a change set" : "runs this version already") + " and keeps running");
            return true;
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
        if (inst.half == null && inst.life.state() != State.FAILED) {
            // A running half stays ACTIVE unless the plan stops it (a replace that changes
            // nothing it runs with leaves it running); a FAILED one stays FAILED, blocked in the
            // planner, until an operator reset (D26).
            inst.life.to(State.UNSATISFIED, "resolving");
        }
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
                failures.cancelRestart(inst);
                changeSets.uninstalled(name, why); // an update's old half kept warm goes too (D38)
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
            Stops.Going g = plans.detach(inst, why);
            if (g != null) {
                rest.add(g);
            }
        }
        stops.submit(rest);
        for (Instance inst : going) {
            instances.remove(inst.name);
            plans.forget(inst.name);
            inst.destroyReason = why;
            if (!stops.stopping(inst)) {
                segments.close(inst);
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
        Collections.reverse(names);
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

    /**
     * The dry run of a change set (D35): its plan and whether it is admitted whole, with the
     * refusal naming the action and the component when not. Changes nothing.
     *
     * @return the text the shell prints, first line {@code change set: ...}, then
     *         {@code refused: ...} or {@code admitted ...}, then the plan
     */
    public ChangeSetResult planChangeSet(ChangeSet set) {
        actor.checkThread();
        return ChangeSetResult.of(set, changeSets.plan(set));
    }

    /**
     * Applies a change set all or nothing (D35): its new halves are prepared while the cell runs,
     * then switched in one actor turn, then the old halves stop. Completes (on the actor) once
     * switched, refused or torn down; when not applied nothing of the cell changed.
     */
    public CompletableFuture<ChangeSetResult> applyChangeSet(ChangeSet set) {
        return applyChangeSet(set, null);
    }

    /** As above, its phases published through {@code shown} (D53; null: an apply of its own). */
    public CompletableFuture<ChangeSetResult> applyChangeSet(ChangeSet set, ChangeSetProgress.Apply shown) {
        actor.checkThread();
        CompletableFuture<ChangeSetResult> f = new CompletableFuture<>();
        changeSets.apply(set, shown, o -> f.complete(ChangeSetResult.of(set, o)));
        return f;
    }

    /** Where the change set being applied is, or how the last one ended (D53); any thread. */
    public ChangeSetProgress changeSetProgress() {
        return changeSetProgress;
    }

    /** {@code to} takes {@code from}'s place in the registry (actor thread): an update's switch or rollback (D38). */
    void swap(Instance from, Instance to) {
        if (!instances.replace(from.name, from, to)) {
            throw new IllegalStateException(from.name + ": not the registered instance");
        }
    }

    /** Removes an instance from the registry (actor thread); a change set uninstalled it. */
    void forget(Instance inst) {
        instances.remove(inst.name, inst);
    }

    /** A dry run. */
    public Plan dryRun(Change change) {
        actor.checkThread();
        return planner.plan(change);
    }

    // ---- management ------------------------------------------------------------------------------

    /**
     * Operator reset: a Failed instance gets a new chance; a running one that moves hardware is
     * allowed to drive outputs again (RESET command).
     */
    public String reset(String name) {
        actor.checkThread();
        return failures.reset(require(name));
    }

    /**
     * Sets a parameter with type, range and mutability checks; returns the applied value.
     *
     * @throws IllegalArgumentException naming the parameter and what is wrong
     */
    public String setParam(String name, String param, String text) {
        actor.checkThread();
        String applied = Parameters.set(require(name), param, text);
        changed();
        return applied;
    }

    /** Reads a parameter as applied (control block when running, configuration otherwise). */
    public String getParam(String name, String param) {
        return Parameters.get(require(name), param);
    }

    /**
     * Periodic sampling on the actor thread: the execution time of each running RT half against
     * its declared WCET ({@link WcetMonitor}).
     *
     * @return total cycles whose execution time exceeded the declared WCET
     */
    public long sample() {
        return wcet.sample();
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
