package org.arflex.drcr.impl.runtime;

import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import java.util.function.Consumer;
import org.arflex.drcr.impl.supervisor.RtHalf;
import org.arflex.planner.Plan;
import org.arflex.planner.Wire;

/**
 * Plans and applies {@link ChangeSet}s (docs/DECISIONS.md D35), on the actor thread: one set at
 * a time, none while an update is in its rollback window. The parts, one job each:
 * {@link SetAdmission} checks and plans a set (the dry run), {@link SetRun} prepares an admitted
 * set while the cell runs (with the shadow runs of updates, {@link ShadowRun}) or tears it down,
 * {@link SwitchTurn} switches it in one actor turn, {@link UpdateWindow} watches an update after
 * its switch and rolls it back or commits it, {@link SetOutcome} is what came of it.
 */
final class ChangeSetExecutor {

    private final Cell cell;
    private final Segments segments;
    private final Consumer<String> log;
    private final SetTools tools;
    private final SetAdmission admission;
    private final SwitchTurn switchTurn;
    /** Where an apply says how far it is (D53). */
    private final ChangeSetProgress progress;
    /** The set being prepared, if any: one at a time (actor thread). */
    private SetRun current;
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
                      Failures failures, Consumer<String> log, ChangeSetProgress progress) {
        this.cell = cell;
        this.progress = progress;
        this.segments = segments;
        this.log = log;
        this.tools = new SetTools(cell, stops, segments, starter, plans, failures, log);
        this.admission = new SetAdmission(cell, stops, starter);
        this.switchTurn = new SwitchTurn(this, tools, warm);
    }

    /** The dry run: what applying {@code set} would do, or why it is refused. Changes nothing. */
    SetOutcome plan(ChangeSet set) {
        SetAdmission.Checked c = admission.check(set, busy());
        return new SetOutcome(false, c.refusal(), c.plan(), 0, 0);
    }

    /** Why no set can be applied now, or null. */
    private String busy() {
        if (current != null) {
            return "another change set is being applied (" + current.set.describe() + ")";
        }
        if (!warm.isEmpty()) {
            return "the update of " + warm.keySet() + " is in its rollback window: "
                    + "a set is applied once it is committed or rolled back";
        }
        return null;
    }

    /**
     * Applies a change set (actor thread). {@code done} gets the outcome on the actor thread,
     * once the set is switched, refused or torn down; nothing of the cell has changed when it
     * is not applied.
     */
    void apply(ChangeSet set, Consumer<SetOutcome> done) {
        apply(set, null, done);
    }

    /**
     * As {@link #apply(ChangeSet, Consumer)}, publishing its phases through {@code shown} (D53);
     * null: through an apply of its own, which this executor also ends with the outcome.
     */
    void apply(ChangeSet set, ChangeSetProgress.Apply shown, Consumer<SetOutcome> done) {
        cell.actor().checkThread();
        ChangeSetProgress.Apply p = shown;
        Consumer<SetOutcome> then = done;
        if (p == null) {
            ChangeSetProgress.Apply own = progress.begin(set.steps().stream().map(ChangeSet.Step::text).toList());
            p = own;
            then = o -> {
                done.accept(o);
                ends(own, o);
            };
        }
        SetAdmission.Checked c = admission.check(set, busy());
        if (c.refusal() != null) {
            log.accept("arflex: change set refused: " + set.describe() + ": " + c.refusal());
            then.accept(new SetOutcome(false, c.refusal(), c.plan(), 0, 0));
            return;
        }
        p.claim(set.steps().stream().filter(ChangeSet.Update.class::isInstance)
                .map(ChangeSet.Step::component).toList());
        SetRun run = new SetRun(tools, switchTurn, p, set, c, then, cell.config().monotonicNs().getAsLong(),
                () -> current = null);
        current = run;
        log.accept("arflex: change set: " + set.describe() + ": preparing " + c.plan().startOrder()
                + " while the cell runs\n" + c.plan().toText());
        run.prepare();
    }

    /** The outcome of an apply this executor began itself, once its windows are over. */
    private static void ends(ChangeSetProgress.Apply own, SetOutcome o) {
        if (!o.applied() || o.verdict() == null) {
            own.done(ChangeSetProgress.outcomeOf(o.applied(), o.refusal(), null, false), o.refusal());
        } else {
            o.verdict().whenComplete((v, e) -> own.done(ChangeSetProgress.outcomeOf(true, null, v, e != null),
                    e != null ? "no verdict of the rollback window: " + e : v));
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

}
