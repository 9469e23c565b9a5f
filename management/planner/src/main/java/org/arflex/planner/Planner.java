package org.arflex.planner;

import java.util.List;
import java.util.Objects;
import java.util.Optional;
import java.util.SortedMap;
import java.util.SortedSet;
import org.arflex.contract.Contract;
import org.arflex.planner.impl.PlanEngine;

/**
 * The cell as the planner sees it (installed contracts, the Active set, blocked components,
 * capacities, measured WCETs) and the one function that plans a change: the entry point of the
 * planner API.
 *
 * <p>{@link #plan(Change)} is the dry run: it computes the {@link Plan} and leaves the state as
 * it was. {@link #apply(Change)} runs the very same computation and then makes the plan's
 * outcome the new state (installed set, Active set, CPU assignment, capacities, measurements):
 * the DRCR calls it and executes the returned plan, which is therefore exactly what
 * {@code plan} showed for the same state and change. When execution deviates (a start fails, a
 * component ends Failed), the DRCR reports it as a change: {@link Change#block}.
 *
 * <p>Admission judges each CPU with a {@link CpuAdmissionTest}, by default
 * {@link CpuAdmissionTest#responseTime()}.
 *
 * <p>Not thread-safe; call from one thread (the DRCR's actor).
 */
public final class Planner {

    private final PlanEngine engine;
    private final CpuAdmissionTest cpuTest;

    /** An empty cell with these capacities, whose CPUs the default test judges. */
    public Planner(Capacities capacities) {
        this(capacities, CpuAdmissionTest.responseTime());
    }

    /** An empty cell with these capacities, whose CPUs {@code cpuTest} judges. */
    public Planner(Capacities capacities, CpuAdmissionTest cpuTest) {
        this.cpuTest = Objects.requireNonNull(cpuTest, "cpuTest");
        this.engine = new PlanEngine(capacities, cpuTest);
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
        return engine.plan(change);
    }

    /**
     * Plans a change with the same computation as {@link #plan(Change)} and makes its outcome
     * the new state.
     *
     * @throws IllegalArgumentException as {@link #plan(Change)}; the state is then unchanged
     */
    public Plan apply(Change change) {
        return engine.apply(change);
    }

    /** The plan of the empty change: the full current picture, normally without actions. */
    public Plan current() {
        return engine.current();
    }

    /** The test admission runs on each CPU. */
    public CpuAdmissionTest cpuAdmissionTest() {
        return cpuTest;
    }

    /** Current capacities. */
    public Capacities capacities() {
        return engine.capacities();
    }

    /** Current measured WCETs, ns, by name. */
    public SortedMap<String, Long> measuredWcetNs() {
        return engine.measuredWcetNs();
    }

    /** Components Active in the current state. */
    public SortedSet<String> active() {
        return engine.active();
    }

    /** Blocked components and why. */
    public SortedMap<String, String> blocked() {
        return engine.blocked();
    }

    /** CPU of every Active periodic or sporadic component. */
    public SortedMap<String, Integer> cpuAssignment() {
        return engine.cpuAssignment();
    }

    /** The installed contract of that name. */
    public Optional<Contract> contract(String name) {
        return engine.contract(name);
    }

    /** Installed contracts, by name. */
    public List<Contract> contracts() {
        return engine.contracts();
    }

    /**
     * Resolver satisfaction of one installed component (ignores admission and blocking).
     *
     * @throws IllegalArgumentException naming it when it is not installed
     */
    public Satisfaction satisfaction(String name) {
        return engine.satisfaction(name);
    }

    /** All resolver wires (every installed component, Active or not), sorted. */
    public List<Wire> wires() {
        return engine.wires();
    }
}
