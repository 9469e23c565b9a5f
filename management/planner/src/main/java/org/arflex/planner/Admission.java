package org.arflex.planner;

import java.util.Collection;
import java.util.Map;
import org.arflex.contract.Contract;

/**
 * Admission control: decides which of the satisfied components the cell can run.
 *
 * <p><b>CPU.</b> Periodic and sporadic tasks are placed on one CPU each, within the
 * {@link org.arflex.contract.Timing#cpus() allowed set} (empty: any capacity CPU). A component
 * that was running keeps its CPU when it still fits there; otherwise CPUs are tried worst-fit
 * (least utilised first, then lowest id). A CPU accepts a task when the total utilisation stays
 * within its cap and the set is schedulable under fixed priorities: first the hyperbolic bound
 * (only when all deadlines are implicit and priorities rate monotonic), then exact response-time
 * analysis of the new task and of every task of lower or equal priority on that CPU. Service
 * tasks take no CPU budget. The WCET used is the larger of the declared and the measured one
 * (noted in the reason).
 *
 * <p><b>Budgets.</b> Memory and network budgets are summed against the capacities.
 *
 * <p><b>Order.</b> Components are admitted by decreasing effective criticality: a provider's is
 * the highest of its own and that of everything depending on it through required inputs, so a
 * provider is never dropped in favour of a less critical component while a more critical one
 * needs it. Ties: components already running first, then name. A cycle of required inputs is
 * admitted or refused as a whole. A component whose provider was refused is refused too, and its
 * reason names the provider. The least critical component is therefore the one refused when
 * everything does not fit.
 */
public final class Admission {

    private Admission() {
    }

    /**
     * Runs admission.
     *
     * @param candidates     the satisfied components to consider
     * @param wires          the resolver's wires (those of required inputs between candidates
     *                       order the admission)
     * @param capacities     what the cell offers
     * @param measuredWcetNs measured WCET by component name, ns (missing or 0: none)
     * @param previousCpu    CPU of each component currently running (kept when it still fits)
     * @return a decision for every candidate
     */
    public static AdmissionResult admit(Collection<Contract> candidates, Collection<Wire> wires,
            Capacities capacities, Map<String, Long> measuredWcetNs, Map<String, Integer> previousCpu) {
        throw new UnsupportedOperationException("API draft");
    }

    /** Runs admission over the satisfied components of {@code resolver}, with nothing running. */
    public static AdmissionResult admit(Resolver resolver, Capacities capacities, Map<String, Long> measuredWcetNs) {
        throw new UnsupportedOperationException("API draft");
    }

}
