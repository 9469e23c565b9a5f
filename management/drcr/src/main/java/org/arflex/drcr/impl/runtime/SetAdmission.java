package org.arflex.drcr.impl.runtime;

import java.util.ArrayList;
import java.util.HashSet;
import java.util.List;
import org.arflex.planner.Change;
import org.arflex.planner.Plan;

/**
 * The admission of a {@link ChangeSet} (D35): every step is checked against the cell (known
 * names, parameters, an update's new version: D38, D41, D42, D47), the whole set becomes one
 * planner {@link Change} and one plan; it is admitted only when every component it installs ends
 * Active and the plan does nothing the set did not name besides starting and rewiring (no other
 * stop, no restart, no hold). A refusal names the action and the component. Changes nothing;
 * actor thread.
 */
final class SetAdmission {

    /** A set checked against the cell and planned; {@code refusal} null when admitted. */
    record Checked(Change change, Plan plan, String refusal) {
    }

    private final Cell cell;
    private final Stops stops;
    private final Starter starter;

    SetAdmission(Cell cell, Stops stops, Starter starter) {
        this.cell = cell;
        this.stops = stops;
        this.starter = starter;
    }

    /**
     * Checks {@code set} against the cell and plans it.
     *
     * @param busy why no set can be applied now (another is being applied, or an update is in its
     *             rollback window), or null
     */
    Checked check(ChangeSet set, String busy) {
        if (set.steps().isEmpty()) {
            return new Checked(Change.none(), null, "the change set has no action");
        }
        if (busy != null) {
            return new Checked(Change.none(), null, busy);
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
        if (inst.half != null && !inst.launching && !starter.launching(n) && stops.pending(n)) {
            return "'" + n + "': a half it ran before is still stopping; apply the set again once it is gone "
                    + "(arflex:list shows one process of it)";
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
}
