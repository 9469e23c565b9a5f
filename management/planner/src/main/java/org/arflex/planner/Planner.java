package org.arflex.planner;

import java.util.List;
import java.util.Optional;
import java.util.SortedMap;
import java.util.SortedSet;
import org.arflex.contract.Contract;

/**
 * The cell as the planner sees it (installed contracts, the Active set, blocked components,
 * capacities, measured WCETs) and the one function that plans a change.
 *
 * <p>{@link #plan(Change)} is the dry run: it computes the {@link Plan} and leaves the state as
 * it was. {@link #apply(Change)} runs the very same computation and then makes the plan's
 * outcome the new state (installed set, Active set, CPU assignment, capacities, measurements):
 * the DRCR calls it and executes the returned plan, which is therefore exactly what
 * {@code plan} showed for the same state and change. When execution deviates (a start fails, a
 * component ends Failed), the DRCR reports it as a change: {@link Change#block}.
 *
 * <p>A plan:
 * <ol>
 * <li>applies the contract part to the resolver (incrementally);</li>
 * <li>admits the satisfied, unblocked components against the new capacities
 * ({@link Admission});</li>
 * <li>STOPs what was Active and is not admitted (uninstalled, unsatisfied, refused, blocked),
 * STARTs what is admitted and was not Active, and RESTARTs what stays Active but was replaced,
 * rewired (its input wires to Active providers changed, or a replaced provider changed the
 * port it feeds it from) or moved to another CPU;</li>
 * <li>orders stops dependents first by the old wiring and starts providers first by the new
 * wiring, a cycle of required inputs as one group.</li>
 * </ol>
 *
 * <p>Not thread-safe; call from one thread (the DRCR's actor).
 */
public final class Planner {

    /** An empty cell with these capacities. */
    public Planner(Capacities capacities) {
        throw new UnsupportedOperationException("API draft");
    }

    /**
     * Plans a change without applying it.
     *
     * @throws IllegalArgumentException naming the component when the change is inconsistent
     *                                  with the cell (install of an installed name, replace or
     *                                  uninstall of an unknown one, a name both installed and
     *                                  uninstalled, block of an unknown one)
     */
    public Plan plan(Change change) {
        throw new UnsupportedOperationException("API draft");
    }

    /**
     * Plans a change with the same computation as {@link #plan(Change)} and makes its outcome
     * the new state.
     *
     * @throws IllegalArgumentException as {@link #plan(Change)}; the state is then unchanged
     */
    public Plan apply(Change change) {
        throw new UnsupportedOperationException("API draft");
    }

    /** The plan of the empty change: the full current picture, normally without actions. */
    public Plan current() {
        return plan(Change.none());
    }

    /** Current capacities. */
    public Capacities capacities() {
        throw new UnsupportedOperationException("API draft");
    }

    /** Current measured WCETs, ns, by name. */
    public SortedMap<String, Long> measuredWcetNs() {
        throw new UnsupportedOperationException("API draft");
    }

    /** Components Active in the current state. */
    public SortedSet<String> active() {
        throw new UnsupportedOperationException("API draft");
    }

    /** Blocked components and why. */
    public SortedMap<String, String> blocked() {
        throw new UnsupportedOperationException("API draft");
    }

    /** CPU of every Active periodic or sporadic component. */
    public SortedMap<String, Integer> cpuAssignment() {
        throw new UnsupportedOperationException("API draft");
    }

    /** The installed contract of that name. */
    public Optional<Contract> contract(String name) {
        throw new UnsupportedOperationException("API draft");
    }

    /** Installed contracts, by name. */
    public List<Contract> contracts() {
        throw new UnsupportedOperationException("API draft");
    }

    /** Resolver satisfaction of one installed component (ignores admission and blocking). */
    public Satisfaction satisfaction(String name) {
        throw new UnsupportedOperationException("API draft");
    }

    /** All resolver wires, sorted. */
    public List<Wire> wires() {
        throw new UnsupportedOperationException("API draft");
    }
}
