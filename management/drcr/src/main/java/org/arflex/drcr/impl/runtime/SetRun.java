package org.arflex.drcr.impl.runtime;

import java.util.ArrayList;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import java.util.function.Consumer;
import org.arflex.drcr.impl.supervisor.RtHalf;
import org.arflex.planner.Plan;

/**
 * One change set being applied (D35), from its preparation to its switch or teardown; actor
 * thread. Its new halves are prepared (segments, spawn, READY on the launch thread) while the
 * old configuration runs and the planner still holds the old state; an update that declares a
 * shadow run (D42) then runs in shadow ({@link ShadowRun}); then {@link SwitchTurn} switches the
 * whole set in one actor turn. A preparation that fails (a spawn fails, a half never gets READY
 * or exits before the switch), a new half that could not take the state again at the switch of
 * its shadow run (D70, {@link ReadoptCheck}: refused once READY), or a rejected shadow run, tears
 * down everything prepared ({@link #abandon}), and the old configuration has not been touched.
 */
final class SetRun {
    final ChangeSet set;
    final SetAdmission.Checked checked;
    final Consumer<SetOutcome> done;
    final long t0;
    final SetTools tools;
    /** Where this apply says how far it is (D53). */
    final ChangeSetProgress.Apply progress;
    private final SwitchTurn switchTurn;
    /** Called once the run no longer holds the executor (switched or torn down). */
    private final Runnable release;
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
    private final Cell cell;
    private final Stops stops;
    private final Segments segments;
    private final Starter starter;
    private final Consumer<String> log;

    SetRun(SetTools tools, SwitchTurn switchTurn, ChangeSetProgress.Apply progress, ChangeSet set, SetAdmission.Checked checked, Consumer<SetOutcome> done, long t0,
           Runnable release) {
        this.tools = tools;
        this.switchTurn = switchTurn;
        this.progress = progress;
        this.set = set;
        this.checked = checked;
        this.done = done;
        this.t0 = t0;
        this.release = release;
        this.cell = tools.cell();
        this.stops = tools.stops();
        this.segments = tools.segments();
        this.starter = tools.starter();
        this.log = tools.log();
    }

    void prepare() {
        Plan plan = checked.plan();
        progress.phase(ChangeSetProgress.PREPARING, "preparing " + set.describe() + " while the cell runs");
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
        preparing();
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
        String cannot = nexts.get(inst.name) == inst ? ReadoptCheck.problem(set, cell.find(inst.name), inst, half) : null;
        if (cannot != null) { // D70: known at READY, before its shadow run's START
            RtHalf running = oldHalves.get(inst.name);
            String refusal = "update " + inst.name + ": refused: " + cannot + "; nothing changed"
                    + (running == null ? "" : " (pid " + running.pid() + " runs " + inst.name + " on)");
            progress.refused(inst.name, refusal, cannot);
            abandon(refusal, "refused before its shadow run: " + inst.name);
            return;
        }
        log.accept("arflex: change set: " + inst.name + " READY (pid " + half.pid() + ", spawn to READY "
                + tookNs / 1000 + " us), not started yet");
        half.exit().thenAccept(ex -> cell.actor().submit(() -> exitedEarly(inst, half, ex)));
        preparing();
        if (outstanding == 0) {
            prepared();
        }
    }

    /** Every half is READY: the shadow runs of updates that declare one (D42), else the switch. */
    private void prepared() {
        for (ChangeSet.Step s : set.steps()) {
            if (s instanceof ChangeSet.Update u && u.shadow() > 0) {
                Instance next = nexts.get(u.component());
                shadows.put(next, new ShadowRun(cell, segments, log, progress, shadowOutcome, u, cell.find(u.component()),
                        oldHalves.get(u.component()), next, prepared.get(next)));
            }
        }
        if (shadows.isEmpty()) {
            switchTurn.switchOver(this);
            return;
        }
        progress.phase(ChangeSetProgress.SHADOW, "shadow runs of " + shadows.keySet().stream().map(i -> i.name).toList()
                + " starting");
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
                switchTurn.switchOver(SetRun.this);
            }
        }

        @Override
        public void rejected(ShadowRun r, String why) {
            if (!over) {
                String refusal = String.format(java.util.Locale.ROOT, "update %s: rejected in shadow after %d cycles: "
                        + "%s; nothing changed (pid %d runs %s on)", r.next.name, r.cycles(), why, r.oldHalf.pid(),
                        r.next.name);
                progress.rejectedInShadow(r.next.name, refusal, why, r.cycles());
                abandon(refusal, "rejected in shadow: " + r.next.name);
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
    void tearDown(String why) {
        abandon("preparation failed, nothing changed: " + why, "change set torn down");
    }

    /** Everything prepared goes, with {@code refusal} as the set's outcome (actor thread). */
    void abandon(String refusal, String stopReason) {
        over = true;
        shadows.values().forEach(ShadowRun::cancel);
        release.run();
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
        done.accept(new SetOutcome(false, refusal, checked.plan(), cell.config().monotonicNs().getAsLong() - t0, 0));
    }

    private void closeUnused(List<Instance> mine) {
        for (Instance inst : mine) {
            if (inst.half == null && !inst.launching && !stops.stopping(inst)
                    && (cell.find(inst.name) != inst || !cell.planner().active().contains(inst.name))) {
                segments.close(inst);
            }
        }
    }

    /** Says which halves are READY and which are awaited, by the action that starts them (D53). */
    private void preparing() {
        List<String> waiting = new ArrayList<>();
        for (Instance inst : starting) {
            if (!prepared.containsKey(inst)) {
                waiting.add(action(inst));
            }
        }
        progress.phase(ChangeSetProgress.PREPARING, String.format(java.util.Locale.ROOT,
                "%d of %d new RT halves READY%s", prepared.size(), starting.size(),
                waiting.isEmpty() ? "" : "; awaiting " + String.join(", ", waiting)));
    }

    /** The action of the set that starts {@code inst}: named in the set, or a start the plan adds. */
    private String action(Instance inst) {
        for (ChangeSet.Step s : set.steps()) {
            if (!(s instanceof ChangeSet.Set) && s.component().equals(inst.name)) {
                return s instanceof ChangeSet.Update ? "update " + inst.name : s.text();
            }
        }
        return "start " + inst.name;
    }

    /** Called by the switch turn: the run no longer holds the executor. */
    void switched() {
        over = true;
        release.run();
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
