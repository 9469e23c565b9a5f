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
import org.arflex.planner.Plan;

/**
 * The switch of a prepared change set (D35), in one actor turn: when the cell is still the one
 * the set was planned on, the planner takes the set, an updated component's registry entry
 * becomes its new version (D38), the new halves are bound and started (or adopted from their
 * shadow run, D42), the running consumers are bound to the new providers (a BIND replaces a
 * binding at the consumer's next cycle boundary, with no UNBIND before it), the parameter writes
 * are applied, and only then are the old halves detached and handed to the stop threads; an
 * update's old half is kept warm for its rollback window ({@link UpdateWindow}). A cell that
 * changed while the set was prepared tears the set down instead.
 */
final class SwitchTurn {
    private final ChangeSetExecutor owner;
    private final Cell cell;
    private final Stops stops;
    private final Segments segments;
    private final Starter starter;
    private final PlanExecutor plans;
    private final Failures failures;
    private final Consumer<String> log;
    /** The executor's updates in their rollback window, by component name. */
    private final Map<String, UpdateWindow> warm;

    SwitchTurn(ChangeSetExecutor owner, SetTools tools, Map<String, UpdateWindow> warm) {
        this.owner = owner;
        this.cell = tools.cell();
        this.stops = tools.stops();
        this.segments = tools.segments();
        this.starter = tools.starter();
        this.plans = tools.plans();
        this.failures = tools.failures();
        this.log = tools.log();
        this.warm = warm;
    }

    /** The switch, in this one actor turn. */
    void switchOver(SetRun run) {
        run.progress.phase(ChangeSetProgress.SWITCHING, "switching " + run.set.describe() + " in one actor turn");
        long ts = cell.config().monotonicNs().getAsLong();
        Plan shown = run.checked.plan();
        for (Instance inst : run.starting) {
            if (run.nexts.get(inst.name) == inst) {
                Instance old = cell.find(inst.name);
                if (old == null || old.half == null || old.half != run.oldHalves.get(inst.name)) {
                    run.tearDown("the running half of '" + inst.name + "' changed while its new version was prepared");
                    return;
                }
            } else if (cell.find(inst.name) != inst) {
                run.tearDown("'" + inst.name + "' was uninstalled while the set was prepared");
                return;
            }
        }
        Plan now;
        try {
            now = cell.planner().plan(run.checked.change());
        } catch (IllegalArgumentException e) {
            run.tearDown("the cell changed while the set was prepared: " + e.getMessage());
            return;
        }
        String differs = differs(shown, now);
        if (differs != null) {
            run.tearDown("the cell changed while the set was prepared: " + differs);
            return;
        }
        run.switched();
        Plan plan = cell.planner().apply(run.checked.change());
        java.util.Set<String> uninstalled = new HashSet<>();
        for (ChangeSet.Step s : run.set.steps()) {
            if (s instanceof ChangeSet.Uninstall) {
                uninstalled.add(s.component());
            }
        }
        // 0. an updated component's registry entry is its new version from now on: the old
        //    half keeps running, bound to its inputs, read by nobody once its consumers follow
        Map<String, Instance> olds = new LinkedHashMap<>();
        for (Instance next : run.nexts.values()) {
            Instance old = cell.find(next.name);
            olds.put(next.name, old);
            old.half = null; // its exit is the rollback window's now, not Failures'
            cell.swap(old, next);
        }
        // 1. the new halves: bound to their providers (running, or prepared here) and started
        for (Instance inst : run.starting) {
            RtHalf half = run.prepared.get(inst);
            inst.planned = true;
            inst.life.target(State.ACTIVE);
            if (inst.life.state() == State.INSTALLED) {
                inst.life.to(State.UNSATISFIED, "change set: switching");
            }
            if (run.shadows.containsKey(inst)) { // bound and started by its shadow run (D42)
                String refused = ShadowSwitch.readopt(olds.get(inst.name), inst, half, log); // D61
                if (refused != null) { // fail closed: the old half keeps the component (D55)
                    stops.submit(List.of(new Stops.Going(inst, half, List.of(), 0, "its state re-adopt was refused")));
                    handBack(inst, olds.get(inst.name), run.oldHalves.get(inst.name), refused);
                    continue;
                }
                starter.adopt(inst, Objects.requireNonNull(half), plan.cpuAssignment().getOrDefault(inst.name, -1),
                        "bound and started by its shadow run");
            } else if (run.nexts.get(inst.name) == inst) {
                // an update's new half that dies before its START, or refuses it: the old half,
                // still running and read by its consumers until step 2, keeps the component (D55)
                starter.activate(inst, Objects.requireNonNull(half), plan.cpuAssignment().getOrDefault(inst.name, -1),
                        inst.params.clone(), plan.wiringOf(inst.name), run.t0, ts,
                        e -> handBack(inst, olds.get(inst.name), run.oldHalves.get(inst.name),
                                "its START was refused (" + e.getMessage() + ")"));
            } else {
                starter.activate(inst, Objects.requireNonNull(half), plan.cpuAssignment().getOrDefault(inst.name, -1),
                        inst.params.clone(), plan.wiringOf(inst.name), run.t0, ts);
            }
        }
        // 2. the running consumers follow: one BIND per input whose provider changes (taken at
        //    its next cycle boundary, the old value read until then), an UNBIND only for an
        //    input that loses its provider
        Map<String, String> why = new LinkedHashMap<>();
        for (Plan.Action a : plan.rewires()) {
            why.put(a.component(), a.reason());
        }
        if (!run.nexts.isEmpty()) {
            // the consumers of an updated component: same provider, the new half's segments
            for (Instance inst : cell.instances()) {
                if (inst.half != null && !run.starting.contains(inst)) {
                    why.putIfAbsent(inst.name, "its provider was updated");
                }
            }
        }
        for (var e : why.entrySet()) {
            Instance inst = cell.find(e.getKey());
            if (inst != null && inst.half != null && !run.starting.contains(inst)) {
                owner.rebind(inst, plan, "the change set (" + e.getValue() + ")");
            }
        }
        // 3. the parameter writes to running components
        for (ChangeSet.Step s : run.set.steps()) {
            if (s instanceof ChangeSet.Set p && !run.paramsBefore.containsKey(cell.find(p.component()))) {
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
            if (inst == null || run.nexts.containsKey(name)) {
                continue; // an updated component's old half is the window's (5.)
            }
            failures.cancelRestart(inst);
            if (uninstalled.contains(name)) {
                inst.life.target(State.DESTROYED);
                gone.add(inst);
            }
            Stops.Going g = plans.detach(inst, "change set: " + run.set.describe());
            if (g != null) {
                going.add(g);
            }
        }
        stops.submit(going);
        for (Instance inst : gone) {
            cell.forget(inst);
            plans.forget(inst.name);
            inst.destroyReason = "uninstalled by change set: " + run.set.describe();
            if (!stops.stopping(inst)) {
                segments.close(inst);
                inst.life.to(State.DESTROYED, inst.destroyReason);
            }
        }
        // 5. the old halves of updated components: kept warm for their window, or stopped now
        List<java.util.concurrent.CompletableFuture<String>> verdicts = new ArrayList<>();
        for (String v : run.shadowVerdicts) {
            verdicts.add(java.util.concurrent.CompletableFuture.completedFuture(v));
        }
        for (ChangeSet.Step s : run.set.steps()) {
            if (s instanceof ChangeSet.Update u) {
                Instance next = run.nexts.get(u.component());
                UpdateWindow w = new UpdateWindow(owner, cell, stops, segments, log, run.progress, warm, run.set, u, olds.get(u.component()), run.oldHalves.get(u.component()), next);
                verdicts.add(w.verdict);
                w.begin();
            }
        }
        long switchNs = cell.config().monotonicNs().getAsLong() - ts;
        // the turn's bounds on CLOCK_MONOTONIC, the clock of every port's t_ns: what a consumer
        // ran around its BIND can be read against them (the switch-window tests)
        log.accept(String.format("arflex: change set %s: switched (prepared in %.1f ms, switch turn %.3f ms, "
                + "monotonic %d..%d ns)", run.set.describe(), (ts - run.t0) / 1e6, switchNs / 1e6, ts, ts + switchNs));
        cell.changed();
        java.util.concurrent.CompletableFuture<String> verdict = verdicts.isEmpty() ? null
                : java.util.concurrent.CompletableFuture.allOf(verdicts.toArray(java.util.concurrent.CompletableFuture[]::new))
                .thenApply(v -> String.join("\n", verdicts.stream().map(java.util.concurrent.CompletableFuture::join).toList()));
        run.done.accept(new SetOutcome(true, null, plan, ts - run.t0, switchNs, verdict));
    }

    /**
     * An update's new half was refused at its START in the switch turn (D55), or its shadow half
     * could not take the running half's state again there (D61): the old half is the
     * component's again before any consumer follows, the planner takes the old contract back, the
     * new instance goes once its half has stopped (the refusal stopped it). Its window then
     * reports the rollback ({@link UpdateWindow#begin}).
     */
    private void handBack(Instance next, Instance old, RtHalf oldHalf, String why) {
        next.bound.clear();
        next.life.target(State.DESTROYED);
        next.destroyReason = why;
        cell.swap(next, old);
        old.half = oldHalf;
        try {
            cell.planner().apply(org.arflex.planner.Change.replace(old.contract));
        } catch (RuntimeException ex) {
            log.accept("arflex: " + next.name + ": the planner refused the old contract back: " + ex.getMessage());
        }
        log.accept("arflex: " + next.name + ": the new version was refused at the switch (" + why + "); pid "
                + oldHalf.pid() + " keeps running it");
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
}
