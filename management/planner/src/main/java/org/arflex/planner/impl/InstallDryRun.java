package org.arflex.planner.impl;

import java.util.ArrayList;
import java.util.Collections;
import java.util.List;
import java.util.Map;
import java.util.Set;
import java.util.TreeMap;
import java.util.TreeSet;
import org.arflex.contract.Contract;
import org.arflex.planner.AdmissionResult;
import org.arflex.planner.Capacities;
import org.arflex.planner.Change;
import org.arflex.planner.CpuAdmissionTest;
import org.arflex.planner.CpuLoad;
import org.arflex.planner.Decision;
import org.arflex.planner.Plan;
import org.arflex.planner.Wire;

/**
 * The plan of installing one component, derived from the plan of no change ({@link
 * CurrentPicture}) instead of planning the whole cell again; {@code null} whenever the result
 * could differ from the full computation, which the caller then runs.
 *
 * <p>Why it is the same: the new component {@code x} is a sink (nothing reads from it, nothing
 * else was rewired), so the resolver's picture is the old one plus {@code x}. When its
 * providers are at least as critical as it is, no effective criticality changes, and the full
 * admission run processes the same groups in the same order with {@code x} inserted where the
 * priority queue would pop it ({@link #insertionPoint}). Everything before that point is placed
 * as before; {@code x} is placed on the state of the CPUs at that point (rebuilt from the trace,
 * {@link ResumedAdmission}); after it, every member is checked to be placed as before: the
 * budgets still fit (or {@code x} took none), and a member that may use the CPU {@code x} went to
 * ({@code k}) was placed first try on its previous CPU, and when that is {@code k}, it still fits
 * there (tested beside {@code x}). Then only the decisions and load of {@code k} change. A
 * member that would choose by utilisation among CPUs including {@code k}, a refusal for budgets
 * that {@code x} changes, an exclusive candidate, a plan of no change that has actions: all give
 * {@code null}.
 */
final class InstallDryRun {

    private InstallDryRun() {
    }

    /**
     * @param base     the plan of no change in the current state, with its admission trace
     * @param resolver the resolver with {@code x} put, {@code delta} what that did
     * @param change   the change (only the install of {@code x})
     */
    static Plan plan(CurrentPicture base, Resolver resolver, ResolveDelta delta, Contract x, Change change,
            Capacities caps, Map<String, Long> measured, Set<String> blocked, CpuAdmissionTest test) {
        Plan b = base.plan();
        AdmissionTrace tr = base.trace();
        String xn = x.name();
        if (!b.actions().isEmpty() || tr.anyExclusive() || !onlyAdds(delta, xn) || !resolver.outputWires(xn).isEmpty()) {
            return null;
        }
        TreeMap<String, String> inactive = new TreeMap<>(b.inactiveAfter());
        // An unsatisfied component's reason lists near misses, which may now name x.
        for (var e : inactive.entrySet()) {
            String n = e.getKey();
            if (!blocked.contains(n) && !resolver.isSatisfied(n)) {
                e.setValue(resolver.satisfaction(n).summary());
            }
        }
        String title = "install " + xn + " " + x.version();
        if (!resolver.isSatisfied(xn)) {
            inactive.put(xn, resolver.satisfaction(xn).summary());
            return new Plan(change, title, List.of(), List.of(), List.of(), b.activeBefore(), b.activeAfter(), inactive,
                    b.wiring(), b.admission(), b.cycles(), b.notes());
        }
        if (x.taskType() != Contract.TaskType.SERVICE && x.timing().exclusive()) {
            return null;
        }
        List<Contract> providers = new ArrayList<>();
        int ready = 0;
        for (String p : resolver.requiredProviders(xn)) {
            AdmissionTrace.Member m = tr.member(p);
            if (m == null || tr.effectiveCriticality(p) < x.criticality()) {
                return null; // not a candidate (blocked upstream), or x would raise its criticality
            }
            providers.add(resolver.contract(p).orElseThrow());
            ready = Math.max(ready, m.step + 1);
        }
        int pos = insertionPoint(tr.steps(), ready, x);
        ResumedAdmission run = new ResumedAdmission(tr, pos, x, providers, resolver.inputWires(xn), caps, measured,
                test);
        AdmissionResult old = b.admission();
        Decision refused = run.admit();
        if (refused != null) {
            TreeMap<String, Decision> ds = new TreeMap<>(old.decisions());
            ds.put(xn, refused);
            inactive.put(xn, refused.reason());
            return new Plan(change, title, List.of(), List.of(), List.of(), b.activeBefore(), b.activeAfter(), inactive,
                    b.wiring(), new AdmissionResult(ds, old.cpus(), old.memoryUsedBytes(), old.networkUsedBps(),
                            old.capacities()), b.cycles(), b.notes());
        }
        int k = run.cpu();
        if (k >= 0) {
            run.adopt(k, n -> resolver.contract(n).orElseThrow());
        }
        if (!laterUnchanged(tr.steps(), pos, k, run.mem(), run.net(), caps, run, resolver)) {
            return null;
        }
        TreeMap<String, Decision> ds = new TreeMap<>(old.decisions());
        List<CpuLoad> loads = old.cpus();
        if (k >= 0) {
            CpuLoad now = run.load(k);
            loads = new ArrayList<>(loads);
            CpuLoad was = null;
            for (int i = 0; i < loads.size(); i++) {
                if (loads.get(i).cpu() == k) {
                    was = loads.set(i, now);
                }
            }
            for (Decision d : run.decisionsOn(k, unchanged(test, was, now, x, old.decisions()))) {
                ds.put(d.component(), d);
            }
        }
        Decision dx = run.decision();
        ds.put(xn, dx);
        AdmissionResult adm = new AdmissionResult(ds, loads, old.memoryUsedBytes() + run.mem(),
                old.networkUsedBps() + run.net(), old.capacities());
        TreeSet<String> after = new TreeSet<>(b.activeAfter());
        after.add(xn);
        List<Wire> wiring = new ArrayList<>(b.wiring());
        List<Wire> mine = new ArrayList<>();
        for (Wire w : resolver.inputWires(xn)) {
            if (after.contains(w.provider())) {
                mine.add(w);
            }
        }
        if (!mine.isEmpty()) {
            int at = Collections.binarySearch(wiring, mine.get(0));
            wiring.addAll(at < 0 ? -at - 1 : at, mine);
        }
        List<Plan.Action> actions = List.of(new Plan.Action(Plan.Op.START, xn, "installed; " + dx.reason()));
        return new Plan(change, title, actions, List.of(), List.of(List.of(xn)), b.activeBefore(), after, inactive,
                wiring, adm, b.cycles(), b.notes());
    }

    /**
     * The decisions on the CPU {@code x} joined that are the same as before, for the default
     * test only: a decision says the CPU, the proof, the utilisation (two decimals) and, under
     * response-time analysis, the response time, which depends only on the tasks of higher or
     * equal priority ({@link FixedPriorityCpu}). So with the same proof and the same utilisation
     * text, a decision is unchanged under the bound, and under response-time analysis for the
     * tasks more urgent than {@code x}.
     */
    private static java.util.function.Function<CpuAdmissionTest.Task, Decision> unchanged(CpuAdmissionTest test,
            CpuLoad was, CpuLoad now, Contract x, Map<String, Decision> old) {
        if (!(test instanceof ResponseTimeTest) || was == null || !was.test().equals(now.test())
                || !Text.util(was.utilisation()).equals(Text.util(now.utilisation()))) {
            return t -> null;
        }
        boolean bound = ResponseTimeTest.HYPERBOLIC.equals(now.test());
        int p = x.timing().priority();
        return t -> bound || t.priority() > p ? old.get(t.name()) : null;
    }

    /** The resolver change added {@code x} and wires into it, and nothing else. */
    private static boolean onlyAdds(ResolveDelta d, String xn) {
        if (!d.added().equals(Set.of(xn)) || !d.removed().isEmpty() || !d.replaced().isEmpty() || !d.rewired().isEmpty()
                || !d.wiresRemoved().isEmpty()) {
            return false;
        }
        for (String s : d.becameSatisfied()) {
            if (!s.equals(xn)) {
                return false;
            }
        }
        for (String s : d.becameUnsatisfied()) {
            if (!s.equals(xn)) {
                return false; // (x itself counts when it comes in unsatisfied)
            }
        }
        for (Wire w : d.wiresAdded()) {
            if (!w.consumer().equals(xn)) {
                return false;
            }
        }
        return true;
    }

    /**
     * Where the full run's priority queue pops {@code x} (a new, not running sink of its own
     * criticality): at the first step after its providers whose group ranks after it (higher
     * effective criticality first, then running, then name).
     */
    static int insertionPoint(List<AdmissionTrace.Step> steps, int ready, Contract x) {
        int c = x.criticality();
        for (int t = ready; t < steps.size(); t++) {
            AdmissionTrace.Step s = steps.get(t);
            if (c > s.effectiveCriticality()
                    || (c == s.effectiveCriticality() && !s.running() && x.name().compareTo(s.firstName()) < 0)) {
                return t;
            }
        }
        return steps.size();
    }

    /**
     * True when every member after {@code pos} is placed as in the trace with {@code x} placed
     * on {@code k} (-1: none) taking {@code dMem} and {@code dNet}; the members kept on {@code k}
     * are added to {@code run} in order.
     */
    private static boolean laterUnchanged(List<AdmissionTrace.Step> steps, int pos, int k, long dMem, long dNet,
            Capacities caps, ResumedAdmission run, Resolver resolver) {
        for (int t = pos; t < steps.size(); t++) {
            AdmissionTrace.Step s = steps.get(t);
            for (AdmissionTrace.Member m : s.members()) {
                if (m.budgetChecked) {
                    if (m.budgetRefused) {
                        if (dMem != 0 || dNet != 0) {
                            return false; // still refused, but the free amount it names changes
                        }
                    } else if (m.memBefore + dMem + m.mem > caps.memoryBytes()
                            || m.netBefore + dNet + m.net > caps.networkBps()) {
                        return false;
                    }
                }
                if (k >= 0 && m.mayUse(k)) {
                    if (!m.prevFirst) {
                        return false; // chose by utilisation among CPUs that include k
                    }
                    if (m.cpu == k && (s.members().size() != 1 || !run.keeps(resolver.contract(m.name).orElseThrow(), k))) {
                        return false;
                    }
                }
            }
        }
        return true;
    }
}
