package org.arflex.drcr.impl.runtime;

import java.util.ArrayList;
import java.util.HashSet;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import java.util.Objects;
import java.util.function.Consumer;
import org.arflex.drcr.impl.lifecycle.State;
import org.arflex.drcr.impl.supervisor.RtHalf;
import org.arflex.planner.Change;
import org.arflex.planner.Plan;
import org.arflex.planner.Wire;

/**
 * Plans and applies {@link ChangeSet}s (docs/DECISIONS.md D35), on the actor thread.
 *
 * <p>Planning: every step is checked against the cell (known names, parameters), the whole set
 * becomes one planner {@link Change} and one plan; it is admitted only when every component it
 * installs ends Active and the plan does nothing the set did not name besides starting and
 * rewiring (no other stop, no restart, no hold). A refusal names the action and the component.
 *
 * <p>Applying: the plan's new halves are prepared (segments, spawn, READY on the launch thread)
 * while the old configuration runs and the planner still holds the old state; then, in one
 * actor turn, the planner takes the set, the new halves are bound and started, the running
 * consumers are bound to the new providers (a BIND replaces a binding at the consumer's next
 * cycle boundary, with no UNBIND before it), the parameter writes are applied, and only then are
 * the old halves detached and handed to the stop threads. A preparation that fails (a spawn
 * fails, a half never gets READY or exits before the switch), or a cell that changed while the
 * set was prepared (its plan is no longer the one shown), tears down everything prepared, and
 * the old configuration has not been touched.
 */
final class ChangeSetExecutor {

    /**
     * What a change set did.
     *
     * @param applied   true when switched
     * @param refusal   why not (null when applied, or when a dry run admits it)
     * @param plan      the plan of the whole set (null when refused before planning)
     * @param prepareNs from the start of preparation to the switch
     * @param switchNs  the switch's actor turn
     */
    record Outcome(boolean applied, String refusal, Plan plan, long prepareNs, long switchNs,
                   java.util.concurrent.CompletableFuture<String> verdict) {

        Outcome(boolean applied, String refusal, Plan plan, long prepareNs, long switchNs) {
            this(applied, refusal, plan, prepareNs, switchNs, null);
        }

        /** The text the shell prints: the refusal or the result, then the plan. */
        String text(ChangeSet set) {
            StringBuilder sb = new StringBuilder();
            sb.append("change set: ").append(set.describe()).append('\n');
            if (refusal != null) {
                sb.append("refused: ").append(refusal).append('\n');
            } else if (applied) {
                sb.append(String.format("applied: prepared in %.1f ms, switched in one actor turn of %.3f ms%n",
                        prepareNs / 1e6, switchNs / 1e6));
            } else {
                sb.append("admitted (dry run: nothing changed)\n");
            }
            if (plan != null) {
                sb.append(plan.toText());
            }
            return sb.toString();
        }
    }

    /** A set checked against the cell and planned. */
    private record Checked(Change change, Plan plan, String refusal) {
    }

    private final Cell cell;
    private final Stops stops;
    private final Segments segments;
    private final Starter starter;
    private final PlanExecutor plans;
    private final Failures failures;
    private final Consumer<String> log;
    /** The set being prepared, if any: one at a time (actor thread). */
    private Run current;
    /** Updates in their rollback window, by component name (actor thread; D38). */
    private final Map<String, UpdateWindow> warm = new LinkedHashMap<>();
    /** How often a rollback window looks at the new half's counters. */
    static final long WATCH_MS = 10;
    /**
     * Cycles with an overrun or a missed deadline the new version may have beyond what the old
     * one, still running on the same inputs, had in the same window: the noise of a machine
     * that is not PREEMPT_RT, where either may miss one under load.
     */
    static final long OVERRUN_ALLOWANCE = 2;

    ChangeSetExecutor(Cell cell, Stops stops, Segments segments, Starter starter, PlanExecutor plans,
                      Failures failures, Consumer<String> log) {
        this.cell = cell;
        this.stops = stops;
        this.segments = segments;
        this.starter = starter;
        this.plans = plans;
        this.failures = failures;
        this.log = log;
    }

    /** The dry run: what applying {@code set} would do, or why it is refused. Changes nothing. */
    Outcome plan(ChangeSet set) {
        Checked c = check(set);
        return new Outcome(false, c.refusal(), c.plan(), 0, 0);
    }

    private Checked check(ChangeSet set) {
        if (set.steps().isEmpty()) {
            return new Checked(Change.none(), null, "the change set has no action");
        }
        if (current != null) {
            return new Checked(Change.none(), null, "another change set is being applied (" + current.set.describe() + ")");
        }
        if (!warm.isEmpty()) {
            return new Checked(Change.none(), null, "the update of " + warm.keySet() + " is in its rollback window: "
                    + "a set is applied once it is committed or rolled back");
        }
        List<String> problems = new ArrayList<>();
        java.util.Set<String> updates = new HashSet<>();
        java.util.Set<String> installs = new HashSet<>();
        java.util.Set<String> uninstalls = new HashSet<>();
        java.util.Set<String> named = new HashSet<>();
        Change.Builder b = Change.builder();
        for (ChangeSet.Step s : set.steps()) {
            String n = s.component();
            Instance inst = cell.find(n);
            if (!(s instanceof ChangeSet.Set) && !named.add(n)) {
                problems.add(s.text() + ": '" + n + "' is named twice");
                continue;
            }
            if (s instanceof ChangeSet.Install) {
                if (inst == null) {
                    problems.add(s.text() + ": no component '" + n + "' is known to the cell (install its bundle, "
                            + "without starting it, first)");
                } else if (inst.planned) {
                    problems.add(s.text() + ": '" + n + "' is installed already (" + inst.life.state() + ")");
                } else if (stops.pending(n) || starter.launching(n)) {
                    problems.add(s.text() + ": a previous RT half of '" + n + "' is still starting or stopping");
                } else {
                    installs.add(n);
                    b.install(inst.contract);
                }
            } else if (s instanceof ChangeSet.Update u) {
                String why = updateProblem(inst, u);
                if (why != null) {
                    problems.add(s.text() + ": " + why);
                } else {
                    updates.add(n);
                    b.replace(u.contract()).overlap(n, u.shadow(), u.window()); // both halves run meanwhile (D51)
                }
            } else if (s instanceof ChangeSet.Uninstall) {
                if (inst == null || !inst.planned) {
                    problems.add(s.text() + ": '" + n + "' is not installed"
                            + (inst == null ? "" : " (" + inst.life.state() + ")"));
                } else {
                    uninstalls.add(n);
                    b.uninstall(n);
                }
            }
        }
        for (ChangeSet.Step s : set.steps()) {
            if (s instanceof ChangeSet.Set p) {
                Instance inst = cell.find(p.component());
                if (inst == null) {
                    problems.add(s.text() + ": no component '" + p.component() + "'");
                } else if (uninstalls.contains(p.component())) {
                    problems.add(s.text() + ": '" + p.component() + "' is uninstalled by this set");
                } else {
                    try {
                        Parameters.check(inst, p.param(), p.value(), !installs.contains(p.component())
                                && !updates.contains(p.component()));
                    } catch (IllegalArgumentException e) {
                        problems.add(s.text() + ": " + e.getMessage());
                    }
                }
            }
        }
        if (!problems.isEmpty()) {
            return new Checked(Change.none(), null, String.join("; ", problems));
        }
        Change change = b.build();
        Plan plan;
        try {
            plan = cell.planner().plan(change);
        } catch (IllegalArgumentException e) {
            return new Checked(change, null, "the planner refused the set: " + e.getMessage());
        }
        List<String> refused = new ArrayList<>();
        for (ChangeSet.Step s : set.steps()) {
            if ((s instanceof ChangeSet.Install || s instanceof ChangeSet.Update)
                    && !plan.activeAfter().contains(s.component())) {
                refused.add(s.text() + ": not admitted: " + plan.inactiveAfter().getOrDefault(s.component(), "not active"));
            }
        }
        for (Plan.Action a : plan.actions()) {
            String n = a.component();
            switch (a.op()) {
                case STOP -> {
                    if (!uninstalls.contains(n)) {
                        refused.add("the set would stop '" + n + "' (" + a.reason() + "): name it in the set");
                    }
                }
                case RESTART -> {
                    if (!updates.contains(n)) { // an update's new half is prepared beside the old one
                        refused.add("the set would restart '" + n + "' (" + a.reason()
                                + "): a change set switches without restarts");
                    }
                }
                case HOLD -> refused.add("the set would hold '" + n + "' in a protective stop (" + a.reason() + ")");
                case START -> {
                    Instance inst = cell.find(n);
                    if (inst == null || inst.half != null || inst.launching || stops.pending(n)) {
                        refused.add("the set would start '" + n + "' while a half of it runs, starts or stops");
                    }
                }
                case REBIND -> {
                }
            }
        }
        refused.addAll(plan.transientRefusals()); // the old and the new half side by side do not fit (D51)
        return new Checked(change, plan, refused.isEmpty() ? null : String.join("; ", refused));
    }

    /** Why {@code inst} cannot be updated to {@code u} in a change set, or null. */
    private String updateProblem(Instance inst, ChangeSet.Update u) {
        String n = u.component();
        if (inst == null || !inst.planned) {
            return "'" + n + "' is not installed" + (inst == null ? "" : " (" + inst.life.state() + ")");
        }
        if (!u.contract().name().equals(n)) {
            return "the new version's contract is of '" + u.contract().name() + "'";
        }
        if (inst.half == null || inst.launching || stops.pending(n) || starter.launching(n)) {
            return "'" + n + "' has no running RT half to update (" + inst.life.state() + "); install or update it "
                    + "outside a change set";
        }
        String state = StateTransfer.problem(inst.contract, u.contract());
        if (state == null) {
            state = StateTransfer.latchProblem(inst); // D52
        }
        if (state != null) {
            return state;
        }
        if (inst.contract.movesHardware() || u.contract().movesHardware()) {
            String beside = StateTransfer.besideProblem(inst.contract, u.contract());
            if (beside != null) {
                return "'" + n + "' moves hardware: " + beside + "; update it outside a change set";
            }
        }
        for (ChangeSet.Envelope e : u.envelopes()) {
            org.arflex.contract.PortSpec out = u.contract().outputs().stream().filter(o -> o.name().equals(e.port()))
                    .findFirst().orElse(null);
            if (out == null) {
                return "envelope " + e + ": the new version has no output '" + e.port() + "'";
            }
            var f = cell.config().types().find(out.type()).flatMap(t -> t.field(e.field())).orElse(null);
            if (f == null || f.padding()) {
                return "envelope " + e + ": port type " + out.type() + " has no field '" + e.field() + "'";
            }
        }
        String tolerance = ShadowRules.problem(cell.config().types(), inst.contract, u);
        if (tolerance != null) {
            return tolerance;
        }
        String id = Instance.generationId(n, inst.generation + 1);
        if (id.length() > 40) {
            return "the new half's object id '" + id + "' is longer than 40 characters (rt-core ABI)";
        }
        return null;
    }

    /**
     * Applies a change set (actor thread). {@code done} gets the outcome on the actor thread,
     * once the set is switched, refused or torn down; nothing of the cell has changed when it
     * is not applied.
     */
    void apply(ChangeSet set, Consumer<Outcome> done) {
        cell.actor().checkThread();
        Checked c = check(set);
        if (c.refusal() != null) {
            log.accept("arflex: change set refused: " + set.describe() + ": " + c.refusal());
            done.accept(new Outcome(false, c.refusal(), c.plan(), 0, 0));
            return;
        }
        Run run = new Run(set, c, done, cell.config().monotonicNs().getAsLong());
        current = run;
        log.accept("arflex: change set: " + set.describe() + ": preparing " + c.plan().startOrder()
                + " while the cell runs\n" + c.plan().toText());
        run.prepare();
    }

    /** One change set being applied (actor thread). */
    private final class Run {
        final ChangeSet set;
        final Checked checked;
        final Consumer<Outcome> done;
        final long t0;
        /** Instances the plan starts, in start order. */
        final List<Instance> starting = new ArrayList<>();
        /** Their READY halves. */
        final Map<Instance, RtHalf> prepared = new LinkedHashMap<>();
        /** Configured parameters of the installed instances before the set (restored on teardown). */
        final Map<Instance, long[]> paramsBefore = new LinkedHashMap<>();
        /** Executables of the installed instances before the set. */
        final Map<Instance, java.nio.file.Path> exeBefore = new LinkedHashMap<>();
        /** Updated components: the new version's instance (not in the registry before the switch). */
        final Map<String, Instance> nexts = new LinkedHashMap<>();
        /** Updated components: the running half when the set was prepared (the switch needs the same). */
        final Map<String, RtHalf> oldHalves = new LinkedHashMap<>();
        /** Updates with a shadow run before the switch (D42), by the new version's instance. */
        final Map<Instance, ShadowRun> shadows = new LinkedHashMap<>();
        /** What the passed shadow runs said, for the verdict. */
        final List<String> shadowVerdicts = new ArrayList<>();
        int outstanding;
        boolean over;

        Run(ChangeSet set, Checked checked, Consumer<Outcome> done, long t0) {
            this.set = set;
            this.checked = checked;
            this.done = done;
            this.t0 = t0;
        }

        void prepare() {
            Plan plan = checked.plan();
            for (ChangeSet.Step s : set.steps()) {
                Instance inst = cell.find(s.component());
                if (s instanceof ChangeSet.Install i) {
                    paramsBefore.put(inst, inst.params);
                    exeBefore.put(inst, inst.executable);
                    inst.executable = i.exe();
                }
            }
            for (ChangeSet.Step s : set.steps()) {
                if (s instanceof ChangeSet.Update u) {
                    Instance old = cell.find(u.component());
                    Instance next = new Instance(u.contract(), old.bundleId, u.exe(), cell.actor(), log, old.generation + 1);
                    next.params = Instance.carried(old.contract, old.params, u.contract());
                    next.life.reason("change set: new version being prepared beside the running one");
                    nexts.put(old.name, next);
                    oldHalves.put(old.name, old.half);
                }
            }
            for (ChangeSet.Step s : set.steps()) {
                if (s instanceof ChangeSet.Set p) {
                    Instance target = nexts.get(p.component());
                    try {
                        if (target != null) {
                            Parameters.set(target, p.param(), p.value()); // the new version starts with it
                        } else if (paramsBefore.containsKey(cell.find(p.component()))) {
                            // the value the new half starts with (its spawn request carries it)
                            Parameters.set(cell.find(p.component()), p.param(), p.value());
                        }
                    } catch (RuntimeException e) {
                        tearDown(s.text() + ": " + e.getMessage());
                        return;
                    }
                }
            }
            for (String name : plan.startOrder()) {
                Instance inst = nexts.containsKey(name) ? nexts.get(name) : cell.find(name);
                starting.add(inst);
                if (!nexts.containsKey(name)) {
                    inst.life.reason("change set: being prepared while the cell runs");
                }
            }
            for (Instance next : nexts.values()) {
                if (!starting.contains(next)) { // a new version the planner sees no reason to restart
                    starting.add(next);
                }
            }
            // every output segment first, so the members of a cycle can bind to each other
            for (Instance inst : starting) {
                try {
                    segments.ensure(inst);
                } catch (java.io.IOException | RuntimeException e) {
                    tearDown("preparing '" + inst.name + "': " + e.getMessage());
                    return;
                }
            }
            outstanding = starting.size();
            if (outstanding == 0) {
                prepared();
                return;
            }
            for (Instance inst : starting) {
                if (over) {
                    break;
                }
                starter.prepare(inst, plan.cpuAssignment().getOrDefault(inst.name, -1),
                        nexts.get(inst.name) == inst ? StateTransfer.source(cell.find(inst.name), inst) : null,
                        (half, error, took) -> ready(inst, half, error, took));
            }
        }

        /** A prepared half is READY, or its launch failed (actor thread). */
        private void ready(Instance inst, RtHalf half, Exception error, long tookNs) {
            outstanding--;
            if (over) {
                if (half != null) {
                    stopQuietly(inst, half, "its change set was torn down");
                }
                return;
            }
            if (error != null || half == null) {
                if (half != null) {
                    prepared.put(inst, half); // READY but its ADOPT refused (D41): stopped with the rest
                }
                tearDown("preparing '" + inst.name + "': " + (error == null ? "no RT half" : error.getMessage()));
                return;
            }
            prepared.put(inst, half);
            log.accept("arflex: change set: " + inst.name + " READY (pid " + half.pid() + ", spawn to READY "
                    + tookNs / 1000 + " us), not started yet");
            half.exit().thenAccept(ex -> cell.actor().submit(() -> exitedEarly(inst, half, ex)));
            if (outstanding == 0) {
                prepared();
            }
        }

        /** Every half is READY: the shadow runs of updates that declare one (D42), else the switch. */
        private void prepared() {
            for (ChangeSet.Step s : set.steps()) {
                if (s instanceof ChangeSet.Update u && u.shadow() > 0) {
                    Instance next = nexts.get(u.component());
                    shadows.put(next, new ShadowRun(cell, segments, log, shadowOutcome, u, cell.find(u.component()),
                            oldHalves.get(u.component()), next, prepared.get(next)));
                }
            }
            if (shadows.isEmpty()) {
                switchOver();
                return;
            }
            for (ShadowRun r : List.copyOf(shadows.values())) {
                if (!over) {
                    r.begin(checked.plan().wiringOf(r.next.name));
                }
            }
        }

        private final ShadowRun.Outcome shadowOutcome = new ShadowRun.Outcome() {
            @Override
            public void passed(ShadowRun r, String summary) {
                if (over) {
                    return;
                }
                shadowVerdicts.add("update " + r.next.name + ": " + summary);
                log.accept("arflex: " + r.next.name + ": the new version (pid " + r.nextHalf.pid() + ") " + summary);
                if (shadowVerdicts.size() == shadows.size()) {
                    switchOver();
                }
            }

            @Override
            public void rejected(ShadowRun r, String why) {
                if (!over) {
                    abandon(String.format(java.util.Locale.ROOT, "update %s: rejected in shadow after %d cycles: %s; "
                            + "nothing changed (pid %d runs %s on)", r.next.name, r.cycles(), why, r.oldHalf.pid(),
                            r.next.name), "rejected in shadow: " + r.next.name);
                }
            }
        };

        private void exitedEarly(Instance inst, RtHalf half, RtHalf.Exit ex) {
            if (!over && prepared.get(inst) == half) {
                prepared.remove(inst);
                half.cleanup();
                ShadowRun shadow = shadows.get(inst);
                if (shadow != null && shadow.exited(ex)) {
                    return; // rejected in shadow (D42)
                }
                tearDown("'" + inst.name + "' (pid " + half.pid() + ") exited before the switch: " + ex.description());
            }
        }

        /** Everything prepared goes; the cell is as it was before the set (actor thread). */
        private void tearDown(String why) {
            abandon("preparation failed, nothing changed: " + why, "change set torn down");
        }

        /** Everything prepared goes, with {@code refusal} as the set's outcome (actor thread). */
        private void abandon(String refusal, String stopReason) {
            over = true;
            shadows.values().forEach(ShadowRun::cancel);
            current = null;
            List<Stops.Going> going = new ArrayList<>();
            for (var e : prepared.entrySet()) {
                going.add(new Stops.Going(e.getKey(), e.getValue(), List.of(), 0, stopReason));
            }
            prepared.clear();
            Stops.Batch b = stops.submit(going);
            List<Instance> mine = List.copyOf(starting);
            // the segments of components that were not running go once their producers are gone
            b.done.thenRun(() -> cell.actor().submit(() -> closeUnused(mine)));
            for (var e : paramsBefore.entrySet()) {
                e.getKey().params = e.getValue();
            }
            for (var e : exeBefore.entrySet()) {
                e.getKey().executable = e.getValue();
            }
            for (Instance inst : starting) {
                if (inst.half == null && "change set: being prepared while the cell runs".equals(inst.life.reason())) {
                    inst.life.reason(inst.planned ? "change set torn down" : "bundle " + inst.bundleId + " is not started");
                }
            }
            log.accept("arflex: change set " + set.describe() + ": " + refusal);
            cell.changed();
            done.accept(new Outcome(false, refusal, checked.plan(), cell.config().monotonicNs().getAsLong() - t0, 0));
        }

        private void closeUnused(List<Instance> mine) {
            for (Instance inst : mine) {
                if (inst.half == null && !inst.launching && !stops.stopping(inst)
                        && (cell.find(inst.name) != inst || !cell.planner().active().contains(inst.name))) {
                    segments.close(inst);
                }
            }
        }

        /** The switch, in this one actor turn. */
        private void switchOver() {
            long ts = cell.config().monotonicNs().getAsLong();
            Plan shown = checked.plan();
            for (Instance inst : starting) {
                if (nexts.get(inst.name) == inst) {
                    Instance old = cell.find(inst.name);
                    if (old == null || old.half == null || old.half != oldHalves.get(inst.name)) {
                        tearDown("the running half of '" + inst.name + "' changed while its new version was prepared");
                        return;
                    }
                } else if (cell.find(inst.name) != inst) {
                    tearDown("'" + inst.name + "' was uninstalled while the set was prepared");
                    return;
                }
            }
            Plan now;
            try {
                now = cell.planner().plan(checked.change());
            } catch (IllegalArgumentException e) {
                tearDown("the cell changed while the set was prepared: " + e.getMessage());
                return;
            }
            String differs = differs(shown, now);
            if (differs != null) {
                tearDown("the cell changed while the set was prepared: " + differs);
                return;
            }
            over = true;
            current = null;
            Plan plan = cell.planner().apply(checked.change());
            java.util.Set<String> uninstalled = new HashSet<>();
            for (ChangeSet.Step s : set.steps()) {
                if (s instanceof ChangeSet.Uninstall) {
                    uninstalled.add(s.component());
                }
            }
            // 0. an updated component's registry entry is its new version from now on: the old
            //    half keeps running, bound to its inputs, read by nobody once its consumers follow
            Map<String, Instance> olds = new LinkedHashMap<>();
            for (Instance next : nexts.values()) {
                Instance old = cell.find(next.name);
                olds.put(next.name, old);
                old.half = null; // its exit is the rollback window's now, not Failures'
                cell.swap(old, next);
            }
            // 1. the new halves: bound to their providers (running, or prepared here) and started
            for (Instance inst : starting) {
                RtHalf half = prepared.get(inst);
                inst.planned = true;
                inst.life.target(State.ACTIVE);
                if (inst.life.state() == State.INSTALLED) {
                    inst.life.to(State.UNSATISFIED, "change set: switching");
                }
                if (shadows.containsKey(inst)) { // bound and started by its shadow run (D42)
                    starter.adopt(inst, Objects.requireNonNull(half), plan.cpuAssignment().getOrDefault(inst.name, -1),
                            "bound and started by its shadow run");
                } else {
                    starter.activate(inst, Objects.requireNonNull(half), plan.cpuAssignment().getOrDefault(inst.name, -1),
                            inst.params.clone(), plan.wiringOf(inst.name), t0, ts);
                }
            }
            // 2. the running consumers follow: one BIND per input whose provider changes (taken at
            //    its next cycle boundary, the old value read until then), an UNBIND only for an
            //    input that loses its provider
            Map<String, String> why = new LinkedHashMap<>();
            for (Plan.Action a : plan.rewires()) {
                why.put(a.component(), a.reason());
            }
            if (!nexts.isEmpty()) {
                // the consumers of an updated component: same provider, the new half's segments
                for (Instance inst : cell.instances()) {
                    if (inst.half != null && !starting.contains(inst)) {
                        why.putIfAbsent(inst.name, "its provider was updated");
                    }
                }
            }
            for (var e : why.entrySet()) {
                Instance inst = cell.find(e.getKey());
                if (inst != null && inst.half != null && !starting.contains(inst)) {
                    rebind(inst, plan, "the change set (" + e.getValue() + ")");
                }
            }
            // 3. the parameter writes to running components
            for (ChangeSet.Step s : set.steps()) {
                if (s instanceof ChangeSet.Set p && !paramsBefore.containsKey(cell.find(p.component()))) {
                    try {
                        Parameters.set(cell.find(p.component()), p.param(), p.value());
                    } catch (RuntimeException e) {
                        log.accept("arflex: change set: " + s.text() + " failed at the switch: " + e.getMessage());
                    }
                }
            }
            // 4. the old halves go (their consumers read the new providers already)
            List<Stops.Going> going = new ArrayList<>();
            List<Instance> gone = new ArrayList<>();
            for (String name : plan.stopOrder()) {
                Instance inst = cell.find(name);
                if (inst == null || nexts.containsKey(name)) {
                    continue; // an updated component's old half is the window's (5.)
                }
                failures.cancelRestart(inst);
                if (uninstalled.contains(name)) {
                    inst.life.target(State.DESTROYED);
                    gone.add(inst);
                }
                Stops.Going g = plans.detach(inst, "change set: " + set.describe());
                if (g != null) {
                    going.add(g);
                }
            }
            stops.submit(going);
            for (Instance inst : gone) {
                cell.forget(inst);
                plans.forget(inst.name);
                inst.destroyReason = "uninstalled by change set: " + set.describe();
                if (!stops.stopping(inst)) {
                    segments.close(inst);
                    inst.life.to(State.DESTROYED, inst.destroyReason);
                }
            }
            // 5. the old halves of updated components: kept warm for their window, or stopped now
            List<java.util.concurrent.CompletableFuture<String>> verdicts = new ArrayList<>();
            for (String v : shadowVerdicts) {
                verdicts.add(java.util.concurrent.CompletableFuture.completedFuture(v));
            }
            for (ChangeSet.Step s : set.steps()) {
                if (s instanceof ChangeSet.Update u) {
                    Instance next = nexts.get(u.component());
                    UpdateWindow w = new UpdateWindow(ChangeSetExecutor.this, cell, stops, segments, log, warm, set, u, olds.get(u.component()), oldHalves.get(u.component()), next);
                    verdicts.add(w.verdict);
                    w.begin();
                }
            }
            long switchNs = cell.config().monotonicNs().getAsLong() - ts;
            log.accept(String.format("arflex: change set %s: switched (prepared in %.1f ms, switch turn %.3f ms)",
                    set.describe(), (ts - t0) / 1e6, switchNs / 1e6));
            cell.changed();
            java.util.concurrent.CompletableFuture<String> verdict = verdicts.isEmpty() ? null
                    : java.util.concurrent.CompletableFuture.allOf(verdicts.toArray(java.util.concurrent.CompletableFuture[]::new))
                    .thenApply(v -> String.join("\n", verdicts.stream().map(java.util.concurrent.CompletableFuture::join).toList()));
            done.accept(new Outcome(true, null, plan, ts - t0, switchNs, verdict));
        }
    }

    /**
     * Binds the running {@code inst} to the providers {@code plan} gives it, under their current
     * object ids: one BIND per input whose segment changes (taken at its next cycle boundary,
     * the old value read until then), an UNBIND only for an input that loses its provider. A
     * refused command kills the half (its restart binds it afresh).
     */
    void rebind(Instance inst, Plan plan, String why) {
        Map<String, String> target = new java.util.TreeMap<>();
        for (Wire w : plan.wiringOf(inst.name)) {
            target.put(w.inPort(), segments.name(w.provider(), w.outPort()));
        }
        if (target.equals(inst.bound)) {
            return;
        }
        try {
            for (var e : target.entrySet()) {
                if (!e.getValue().equals(inst.bound.get(e.getKey()))) {
                    inst.half.bind(e.getKey(), e.getValue());
                    inst.bound.put(e.getKey(), e.getValue());
                }
            }
            for (String port : List.copyOf(inst.bound.keySet())) {
                if (!target.containsKey(port)) {
                    inst.half.unbind(port);
                    inst.bound.remove(port);
                }
            }
            log.accept("arflex: " + inst.name + " rewired by " + why + "; inputs " + inst.bound);
        } catch (java.io.IOException | RuntimeException e) {
            log.accept("arflex: " + inst.name + ": rewiring failed: " + e.getMessage() + "; restarting it");
            inst.half.kill();
        }
    }

    /**
     * A half's exit that {@link Failures} would handle (actor thread): the new version of an
     * update in its rollback window is rolled back instead of restarted.
     *
     * @return true when handled here
     */
    boolean exited(Instance inst, RtHalf half, RtHalf.Exit ex) {
        UpdateWindow w = warm.get(inst.name);
        if (w == null || w.next != inst || w.nextHalf != half) {
            return false;
        }
        w.rollback("the new version (pid " + half.pid() + ") exited: " + ex.description(), ex.seenNanos());
        return true;
    }

    /** Component {@code name} is uninstalled (actor thread): its window ends, its old half stops. */
    void uninstalled(String name, String why) {
        UpdateWindow w = warm.get(name);
        if (w != null) {
            w.end("its old version stopped: " + why, w.cyclesNow());
        }
    }

    static org.arflex.drcr.impl.abi.ControlBlock.Stats stats(RtHalf half, Instance inst) {
        try {
            return half.exit().isDone() ? null : half.stats(inst.contract.timing().wcetNs());
        } catch (RuntimeException e) {
            return null;
        }
    }

    static long bad(org.arflex.drcr.impl.abi.ControlBlock.Stats s) {
        return s == null ? 0 : s.overruns() + s.deadlineMisses();
    }

    /** Null when {@code now} does what {@code shown} said, else what differs. */
    static String differs(Plan shown, Plan now) {
        if (!shown.actions().stream().map(a -> a.op() + " " + a.component()).toList()
                .equals(now.actions().stream().map(a -> a.op() + " " + a.component()).toList())) {
            return "actions " + now.actions().stream().map(a -> a.op() + " " + a.component()).toList();
        }
        if (!shown.wiring().equals(now.wiring())) {
            return "wiring " + now.wiring();
        }
        if (!shown.cpuAssignment().equals(now.cpuAssignment())) {
            return "cpus " + now.cpuAssignment();
        }
        if (!shown.transientRefusals().equals(now.transientRefusals())) {
            return "while both halves run: " + now.transientRefusals();
        }
        return null;
    }

    private void stopQuietly(Instance inst, RtHalf half, String why) {
        Stops.Batch b = stops.submit(List.of(new Stops.Going(inst, half, List.of(), 0, why)));
        b.done.thenRun(() -> cell.actor().submit(() -> {
            if (inst.half == null && !inst.launching && !stops.stopping(inst)
                    && (cell.find(inst.name) != inst || !cell.planner().active().contains(inst.name))) {
                segments.close(inst);
            }
        }));
    }
}
