package org.arflex.planner.impl;

import java.util.ArrayList;
import java.util.Collections;
import java.util.HashMap;
import java.util.List;
import java.util.Map;
import java.util.Objects;
import java.util.Optional;
import java.util.SortedMap;
import java.util.SortedSet;
import java.util.TreeMap;
import java.util.TreeSet;
import org.arflex.contract.Contract;
import org.arflex.planner.Capacities;
import org.arflex.planner.Change;
import org.arflex.planner.CpuAdmissionTest;
import org.arflex.planner.Plan;
import org.arflex.planner.Satisfaction;
import org.arflex.planner.Wire;

/**
 * The engine behind {@link org.arflex.planner.Planner}: the cell as the planner sees it
 * (installed contracts, the Active set, blocked components, capacities, measured WCETs) and the
 * one function that plans a change.
 *
 * <p>A plan:
 * <ol>
 * <li>applies the contract part to the resolver (incrementally);</li>
 * <li>admits the satisfied, unblocked components against the new capacities
 * ({@link Admission}, each CPU judged by the {@link CpuAdmissionTest}); a blocked component
 * takes its dependents down as a missing provider would;</li>
 * <li>STOPs what was Active and is not admitted (uninstalled, unsatisfied, refused, blocked),
 * STARTs what is admitted and was not Active, and RESTARTs what stays Active but was replaced,
 * rewired (its input wires to Active providers changed, or a replaced provider changed the
 * port it feeds it from) or moved to another CPU;</li>
 * <li>orders stops dependents first by the old wiring and starts providers first by the new
 * wiring, a cycle as one group.</li>
 * </ol>
 *
 * <p>Not thread-safe; call from one thread (the DRCR's actor).
 */
public final class PlanEngine {

    private final Resolver resolver = new Resolver();
    private final TreeSet<String> active = new TreeSet<>();
    private final TreeMap<String, String> blocked = new TreeMap<>();
    private final TreeMap<String, Long> measured = new TreeMap<>();
    private final TreeMap<String, Integer> cpuOf = new TreeMap<>();
    /** Components admission refused at the last apply, with the reason (for START reasons). */
    private final TreeMap<String, String> lastRefused = new TreeMap<>();
    private final CpuAdmissionTest cpuTest;
    private Capacities capacities;
    /** Derive the plan of one install from {@link #picture} when it is provably the same. */
    private final boolean incremental;
    /** The plan of no change in the current state, once asked; null after a commit. */
    private CurrentPicture picture;
    /** How many plans {@link InstallDryRun} derived (for tests). */
    private long derived;
    private final FullPlan fullPlan;

    /** An empty cell with these capacities, whose CPUs {@code cpuTest} judges. */
    public PlanEngine(Capacities capacities, CpuAdmissionTest cpuTest) {
        this(capacities, cpuTest, true);
    }

    /** As {@link #PlanEngine(Capacities, CpuAdmissionTest)}; {@code incremental} false always plans in full (tests). */
    PlanEngine(Capacities capacities, CpuAdmissionTest cpuTest, boolean incremental) {
        this.capacities = Objects.requireNonNull(capacities, "capacities");
        this.cpuTest = Objects.requireNonNull(cpuTest, "cpuTest");
        this.incremental = incremental;
        this.fullPlan = new FullPlan(resolver, active, measured, cpuOf, lastRefused, this.cpuTest);
    }

    /** How many plans were derived from the plan of no change instead of computed in full. */
    long derivedPlans() {
        return derived;
    }

    /**
     * Plans a change without applying it.
     *
     * @throws IllegalArgumentException naming the component when the change is inconsistent
     *                                  with the cell (install of an installed name, replace or
     *                                  uninstall of an unknown one, a name in two parts that
     *                                  exclude each other, block or measurement of an unknown
     *                                  one, unblock of one that is not blocked)
     */
    public Plan plan(Change change) {
        return compute(change, false);
    }

    /**
     * Plans a change with the same computation as {@link #plan(Change)} and makes its outcome
     * the new state.
     *
     * @throws IllegalArgumentException as {@link #plan(Change)}; the state is then unchanged
     */
    public Plan apply(Change change) {
        return compute(change, true);
    }

    /** The plan of the empty change: the full current picture, normally without actions. */
    public Plan current() {
        return picture().plan();
    }

    private CurrentPicture picture() {
        if (picture == null) {
            AdmissionTrace trace = new AdmissionTrace();
            Plan p = compute(Change.none(), false, trace);
            picture = new CurrentPicture(p, trace);
        }
        return picture;
    }

    /** Current capacities. */
    public Capacities capacities() {
        return capacities;
    }

    /** Current measured WCETs, ns, by name. */
    public SortedMap<String, Long> measuredWcetNs() {
        return Collections.unmodifiableSortedMap(new TreeMap<>(measured));
    }

    /** Components Active in the current state. */
    public SortedSet<String> active() {
        return Collections.unmodifiableSortedSet(new TreeSet<>(active));
    }

    /** Blocked components and why. */
    public SortedMap<String, String> blocked() {
        return Collections.unmodifiableSortedMap(new TreeMap<>(blocked));
    }

    /** CPU of every Active periodic or sporadic component. */
    public SortedMap<String, Integer> cpuAssignment() {
        return Collections.unmodifiableSortedMap(new TreeMap<>(cpuOf));
    }

    /** The installed contract of that name. */
    public Optional<Contract> contract(String name) {
        return resolver.contract(name);
    }

    /** Installed contracts, by name. */
    public List<Contract> contracts() {
        return resolver.contracts();
    }

    /**
     * Resolver satisfaction of one installed component (ignores admission and blocking).
     *
     * @throws IllegalArgumentException naming it when it is not installed
     */
    public Satisfaction satisfaction(String name) {
        return resolver.satisfaction(name);
    }

    /** All resolver wires, sorted. */
    public List<Wire> wires() {
        return resolver.wires();
    }

    // ------------------------------------------------------------------------------------------

    private Plan compute(Change change, boolean commit) {
        return compute(change, commit, null);
    }

    /** Plans in full, or derives the plan of one install (both validate first). */
    private Plan compute(Change change, boolean commit, AdmissionTrace trace) {
        Objects.requireNonNull(change, "change");
        // 1. Validate against the current state; nothing is touched before this passes.
        CheckedChange checked = CheckedChange.check(change, resolver, blocked, measured, capacities);
        Map<String, Contract> puts = checked.puts;
        TreeSet<String> installed = checked.installed;
        TreeMap<String, Contract> replaced = checked.replaced; // name -> old contract
        TreeMap<String, Contract> uninstalled = checked.uninstalled;
        TreeMap<String, String> newBlocked = checked.newBlocked;
        TreeMap<String, Long> newMeasured = checked.newMeasured;
        Capacities newCaps = checked.newCaps;

        if (incremental && trace == null && installed.size() == 1 && puts.size() == 1 && uninstalled.isEmpty()
                && change.blocks().isEmpty() && change.unblocks().isEmpty() && change.measuredWcetNs().isEmpty()
                && change.capacities().isEmpty() && change.overlaps().isEmpty() && change.cause().isEmpty()) {
            Plan p = derive(change, puts.values().iterator().next(), commit, newBlocked, newMeasured);
            if (p != null) {
                return p;
            }
        }

        // 2. The picture before: effective input wiring of the Active components.
        Map<String, List<Wire>> oldEff = new HashMap<>();
        for (String n : active) {
            oldEff.put(n, fullPlan.effective(n, active));
        }
        Map<String, Contract> oldContracts = new HashMap<>();
        oldContracts.putAll(replaced);
        oldContracts.putAll(uninstalled);

        // 3. Apply the contract part; undone at the end of a dry run (or on failure).
        List<Contract> changedPuts = new ArrayList<>();
        for (Contract c : puts.values()) {
            if (!replaced.containsKey(c.name()) && !installed.contains(c.name())) {
                continue; // identical replacement
            }
            changedPuts.add(c);
        }
        resolver.apply(changedPuts, uninstalled.keySet());
        boolean done = false;
        try {
            Plan plan = fullPlan.build(change, installed, replaced, uninstalled, newBlocked, newMeasured, newCaps, oldEff,
                    oldContracts, trace, capacities);
            if (commit) {
                commit(plan, newBlocked, newMeasured, newCaps);
            }
            done = true;
            return plan;
        } finally {
            if (!commit || !done) {
                List<Contract> restore = new ArrayList<>();
                for (Contract c : changedPuts) {
                    if (replaced.containsKey(c.name())) {
                        restore.add(replaced.get(c.name()));
                    }
                }
                restore.addAll(uninstalled.values());
                resolver.apply(restore, installed);
            }
        }
    }

    /**
     * The plan of installing {@code x} derived from the plan of no change, or null when it may
     * differ from the full computation ({@link InstallDryRun}). Leaves the state as it was,
     * unless committing.
     */
    private Plan derive(Change change, Contract x, boolean commit, SortedMap<String, String> newBlocked,
            SortedMap<String, Long> newMeasured) {
        CurrentPicture base = picture();
        ResolveDelta delta = resolver.put(x);
        boolean keep = false;
        try {
            Plan plan;
            try {
                plan = InstallDryRun.plan(base, resolver, delta, x, change, capacities, measured, blocked.keySet(),
                        cpuTest);
            } catch (ReplayRefused e) {
                plan = null; // a test whose state the trace cannot rebuild: plan in full
            }
            if (plan != null) {
                derived++;
                if (commit) {
                    commit(plan, newBlocked, newMeasured, capacities);
                    keep = true;
                }
            }
            return plan;
        } finally {
            if (!keep) {
                resolver.remove(x.name());
            }
        }
    }

    /** Makes a plan's outcome the state. */
    private void commit(Plan plan, SortedMap<String, String> newBlocked, SortedMap<String, Long> newMeasured,
            Capacities newCaps) {
        picture = null;
        active.clear();
        active.addAll(plan.activeAfter());
        cpuOf.clear();
        cpuOf.putAll(plan.cpuAssignment());
        blocked.clear();
        blocked.putAll(newBlocked);
        measured.clear();
        measured.putAll(newMeasured);
        capacities = newCaps;
        lastRefused.clear();
        lastRefused.putAll(plan.admission().refused());
    }
}
