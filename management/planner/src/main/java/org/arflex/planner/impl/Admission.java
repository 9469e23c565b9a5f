package org.arflex.planner.impl;

import java.util.ArrayList;
import java.util.Collection;
import java.util.List;
import java.util.Map;
import java.util.Set;
import org.arflex.contract.Contract;
import org.arflex.contract.Timing;
import org.arflex.planner.AdmissionResult;
import org.arflex.planner.Capacities;
import org.arflex.planner.CpuAdmissionTest;
import org.arflex.planner.Wire;

/**
 * Admission control: decides which of the satisfied components the cell can run.
 *
 * <p><b>CPU.</b> Periodic and sporadic tasks are placed on one CPU each, within the
 * {@link org.arflex.contract.Timing#cpus() allowed set} (empty: any capacity CPU). A component
 * that was running keeps its CPU when it still fits there; otherwise CPUs are tried worst-fit
 * (least utilised first, then lowest id). A CPU accepts a task when the total utilisation stays
 * within its cap and the {@link CpuAdmissionTest} accepts it (by default {@link ResponseTimeTest}:
 * the hyperbolic bound when all deadlines are implicit and priorities rate monotonic, else exact
 * response-time analysis of the new task and of every task it can delay). Service
 * tasks take no CPU budget. The WCET used is the larger of the declared and the measured one
 * (noted in the reason).
 *
 * <p><b>CPUs kept apart.</b> A task whose timing is {@link Timing#exclusive() exclusive}
 * (SPEC §8.6) goes only to a CPU holding no other task, and no task is placed on that CPU after
 * it; tasks that share CPUs try the CPUs that no exclusive candidate names last. A
 * {@link Capacities.Cpu#reserved() reserved} CPU takes only tasks whose contract names it.
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
     * Runs admission; the components in {@code previousCpu} count as running.
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
        return admit(candidates, wires, capacities, measuredWcetNs, previousCpu, previousCpu.keySet());
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
     * @param running        components currently running (preferred at equal criticality)
     * @return a decision for every candidate
     */
    public static AdmissionResult admit(Collection<Contract> candidates, Collection<Wire> wires,
            Capacities capacities, Map<String, Long> measuredWcetNs, Map<String, Integer> previousCpu,
            Set<String> running) {
        return admit(candidates, wires, capacities, measuredWcetNs, previousCpu, running, new ResponseTimeTest());
    }

    /**
     * Runs admission, each CPU judged by {@code cpuTest}.
     *
     * @param candidates     the satisfied components to consider
     * @param wires          the resolver's wires (those of required inputs between candidates
     *                       order the admission)
     * @param capacities     what the cell offers
     * @param measuredWcetNs measured WCET by component name, ns (missing or 0: none)
     * @param previousCpu    CPU of each component currently running (kept when it still fits)
     * @param running        components currently running (preferred at equal criticality)
     * @param cpuTest        the schedulability test of one CPU
     * @return a decision for every candidate
     */
    public static AdmissionResult admit(Collection<Contract> candidates, Collection<Wire> wires,
            Capacities capacities, Map<String, Long> measuredWcetNs, Map<String, Integer> previousCpu,
            Set<String> running, CpuAdmissionTest cpuTest) {
        return new AdmissionRun(candidates, wires, capacities, measuredWcetNs, previousCpu, running, cpuTest, null).run();
    }

    /** As {@link #admit(Collection, Collection, Capacities, Map, Map, Set, CpuAdmissionTest)}, recording the run. */
    static AdmissionResult admit(Collection<Contract> candidates, Collection<Wire> wires, Capacities capacities,
            Map<String, Long> measuredWcetNs, Map<String, Integer> previousCpu, Set<String> running,
            CpuAdmissionTest cpuTest, AdmissionTrace trace) {
        return new AdmissionRun(candidates, wires, capacities, measuredWcetNs, previousCpu, running, cpuTest, trace).run();
    }

    /** Runs admission over the satisfied components of {@code resolver}, with nothing running. */
    public static AdmissionResult admit(Resolver resolver, Capacities capacities, Map<String, Long> measuredWcetNs) {
        List<Contract> cands = new ArrayList<>();
        for (String n : resolver.satisfied()) {
            cands.add(resolver.contract(n).orElseThrow());
        }
        return admit(cands, resolver.wires(), capacities, measuredWcetNs, Map.of(), Set.of());
    }
}
