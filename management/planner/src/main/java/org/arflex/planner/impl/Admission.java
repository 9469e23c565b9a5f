package org.arflex.planner.impl;

import java.util.ArrayList;
import java.util.Collection;
import java.util.Comparator;
import java.util.HashMap;
import java.util.HashSet;
import java.util.List;
import java.util.Map;
import java.util.OptionalInt;
import java.util.PriorityQueue;
import java.util.Set;
import java.util.TreeMap;
import java.util.TreeSet;
import java.util.function.Function;
import org.arflex.contract.Contract;
import org.arflex.contract.PortSpec;
import org.arflex.contract.Timing;
import org.arflex.planner.AdmissionResult;
import org.arflex.planner.Capacities;
import org.arflex.planner.CpuAdmissionTest;
import org.arflex.planner.CpuAdmissionTest.Task;
import org.arflex.planner.CpuLoad;
import org.arflex.planner.Decision;
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
        return new Run(candidates, wires, capacities, measuredWcetNs, previousCpu, running, cpuTest, null).run();
    }

    /** As {@link #admit(Collection, Collection, Capacities, Map, Map, Set, CpuAdmissionTest)}, recording the run. */
    static AdmissionResult admit(Collection<Contract> candidates, Collection<Wire> wires, Capacities capacities,
            Map<String, Long> measuredWcetNs, Map<String, Integer> previousCpu, Set<String> running,
            CpuAdmissionTest cpuTest, AdmissionTrace trace) {
        return new Run(candidates, wires, capacities, measuredWcetNs, previousCpu, running, cpuTest, trace).run();
    }

    /** Runs admission over the satisfied components of {@code resolver}, with nothing running. */
    public static AdmissionResult admit(Resolver resolver, Capacities capacities, Map<String, Long> measuredWcetNs) {
        List<Contract> cands = new ArrayList<>();
        for (String n : resolver.satisfied()) {
            cands.add(resolver.contract(n).orElseThrow());
        }
        return admit(cands, resolver.wires(), capacities, measuredWcetNs, Map.of(), Set.of());
    }

    /** One capacity CPU during a run: placement state here, schedulability in {@link #analysis}. */
    static final class Cpu {
        final int id;
        final double cap;
        final boolean reserved;
        private final CpuAdmissionTest test;
        /** The test's state; null until first needed on a CPU resumed from a trace. */
        private CpuAdmissionTest.Cpu analysis;
        final List<Task> tasks = new ArrayList<>();
        double util;
        /** The exclusive task placed here, or null. */
        String owner;
        /** Where to record adds, or null. */
        AdmissionTrace trace;
        int step;

        Cpu(Capacities.Cpu c, CpuAdmissionTest test) {
            this.id = c.id();
            this.cap = c.utilisationCap();
            this.reserved = c.reserved();
            this.test = test;
            this.analysis = test.open(c.id());
        }

        /**
         * The CPU as a recorded run left it after {@code tasks} were added in this order: the
         * placement state now, the test's state when first asked (the adds replayed, each after
         * its test, as the run did them; the test's contract makes its state depend on nothing
         * else).
         */
        Cpu(Capacities.Cpu c, CpuAdmissionTest test, List<Task> placed) {
            this.id = c.id();
            this.cap = c.utilisationCap();
            this.reserved = c.reserved();
            this.test = test;
            for (Task t : placed) {
                util += t.utilisation();
                tasks.add(t);
            }
        }

        CpuAdmissionTest.Cpu analysis() {
            if (analysis == null) {
                analysis = test.open(id);
                for (Task t : tasks) {
                    String no = analysis.test(t);
                    if (no != null) {
                        throw new ReplayRefused("cpu " + id + ": replay of '" + t.name() + "' refused: " + no);
                    }
                    analysis.add(t);
                }
            }
            return analysis;
        }

        /** Why {@code t} may not share this CPU (SPEC §8.6), or null. */
        String exclusion(Task t, boolean exclusive) {
            if (owner != null) {
                return "cpu " + id + ": held exclusively by '" + owner + "' (timing/@exclusive)";
            }
            if (exclusive && !tasks.isEmpty()) {
                List<String> names = new ArrayList<>();
                for (Task e : tasks) {
                    names.add("'" + e.name() + "'");
                }
                names.sort(null);
                return "cpu " + id + ": '" + t.name() + "' asks for a cpu of its own (timing/@exclusive), but cpu "
                        + id + " already holds " + String.join(", ", names);
            }
            return null;
        }

        /** Null when {@code t} fits here (cap, then the test), else why not. */
        String test(Task t) {
            double u = util + t.utilisation();
            if (u > cap + 1e-9) {
                return "cpu " + id + ": utilisation " + Text.util(u) + " with '" + t.name() + "' exceeds cap "
                        + Text.util(cap);
            }
            String no = analysis().test(t);
            return no == null ? null : "cpu " + id + ": " + no;
        }

        /** Adds a task that passed {@link #test}; returns the undo step. */
        Runnable add(Task t) {
            Runnable undo = analysis().add(t);
            double oldUtil = util;
            util += t.utilisation();
            tasks.add(t);
            AdmissionTrace tr = trace;
            if (tr != null) {
                tr.added(id, step, t);
            }
            return () -> {
                tasks.remove(t);
                util = oldUtil;
                undo.run();
                if (tr != null) {
                    tr.removedLast(id);
                }
            };
        }
    }

    /** One admission run. */
    private static final class Run {
        final TreeMap<String, Contract> cands = new TreeMap<>();
        final Map<String, List<Wire>> requiredIn = new HashMap<>();
        final Capacities caps;
        final Map<String, Long> measured;
        final Map<String, Integer> previousCpu;
        final Set<String> running;
        final TreeMap<Integer, Cpu> cpus = new TreeMap<>();
        final TreeMap<String, Decision> decisions = new TreeMap<>();
        final Map<String, Cpu> placedOn = new HashMap<>();
        final Map<String, Task> taskOf = new HashMap<>();
        final Map<String, String> notes = new HashMap<>();
        final Set<String> admitted = new HashSet<>();
        /** CPUs named in {@code timing/@cpus} by an exclusive candidate not admitted yet: count per CPU. */
        final Map<Integer, Integer> wantedExclusively = new HashMap<>();
        long memUsed;
        long netUsed;
        final AdmissionTrace trace;
        AdmissionTrace.Step step;
        final Map<String, AdmissionTrace.Member> traced = new HashMap<>();

        Run(Collection<Contract> candidates, Collection<Wire> wires, Capacities caps, Map<String, Long> measured,
                Map<String, Integer> previousCpu, Set<String> running, CpuAdmissionTest cpuTest, AdmissionTrace trace) {
            this.trace = trace;
            for (Contract c : candidates) {
                if (cands.put(c.name(), c) != null) {
                    throw new IllegalArgumentException("candidate '" + c.name() + "' given twice");
                }
            }
            for (Wire w : wires) {
                Contract c = cands.get(w.consumer());
                if (c == null) {
                    continue;
                }
                PortSpec in = null;
                for (PortSpec ps : c.ports()) {
                    if (ps.name().equals(w.inPort())) {
                        in = ps;
                        break;
                    }
                }
                if (in != null && in.direction() == PortSpec.Direction.IN && !in.optional()) {
                    requiredIn.computeIfAbsent(w.consumer(), k -> new ArrayList<>()).add(w);
                }
            }
            for (List<Wire> l : requiredIn.values()) {
                l.sort(null);
            }
            this.caps = caps;
            this.measured = measured;
            this.previousCpu = previousCpu;
            this.running = running;
            for (Capacities.Cpu c : caps.cpus()) {
                Cpu cpu = new Cpu(c, cpuTest);
                cpu.trace = trace;
                cpus.put(c.id(), cpu);
            }
            for (Contract c : cands.values()) {
                if (isExclusive(c)) {
                    if (trace != null) {
                        trace.exclusiveCandidate();
                    }
                    for (int id : new TreeSet<>(c.timing().cpus())) {
                        wantedExclusively.merge(id, 1, Integer::sum);
                    }
                }
            }
        }

        static boolean isExclusive(Contract c) {
            return c.taskType() != Contract.TaskType.SERVICE && c.timing().exclusive();
        }

        final Map<String, Set<String>> providerCache = new HashMap<>();

        Set<String> providersOf(String n) {
            List<Wire> ws = requiredIn.get(n);
            if (ws == null) {
                return Set.of();
            }
            return providerCache.computeIfAbsent(n, k -> {
                Set<String> s = new TreeSet<>();
                for (Wire w : ws) {
                    s.add(w.provider());
                }
                return s;
            });
        }

        AdmissionResult run() {
            List<List<String>> groups = Graphs.dependencyOrder(cands.keySet(), this::providersOf);
            int g = groups.size();
            Map<String, Integer> groupOf = new HashMap<>();
            for (int i = 0; i < g; i++) {
                for (String n : groups.get(i)) {
                    groupOf.put(n, i);
                }
            }
            List<Set<Integer>> consumersOf = new ArrayList<>();
            List<Set<Integer>> providersOfGroup = new ArrayList<>();
            for (int i = 0; i < g; i++) {
                consumersOf.add(new HashSet<>());
                providersOfGroup.add(new HashSet<>());
            }
            for (int i = 0; i < g; i++) {
                for (String n : groups.get(i)) {
                    for (String p : providersOf(n)) {
                        Integer j = groupOf.get(p);
                        if (j != null && j != i) {
                            consumersOf.get(j).add(i);
                            providersOfGroup.get(i).add(j);
                        }
                    }
                }
            }
            // Effective criticality: consumers before providers (reverse dependency order).
            int[] eff = new int[g];
            boolean[] isRunning = new boolean[g];
            for (int i = g - 1; i >= 0; i--) {
                int e = Integer.MIN_VALUE;
                for (String n : groups.get(i)) {
                    e = Math.max(e, cands.get(n).criticality());
                    isRunning[i] |= running.contains(n);
                }
                for (int c : consumersOf.get(i)) {
                    e = Math.max(e, eff[c]);
                }
                eff[i] = e;
            }
            int[] pending = new int[g];
            // Rank every group once by (effective criticality desc, running first, name); the
            // queue then compares plain ints.
            Integer[] byKey = new Integer[g];
            for (int i = 0; i < g; i++) {
                byKey[i] = i;
            }
            java.util.Arrays.sort(byKey, Comparator.comparingInt((Integer i) -> -eff[i])
                    .thenComparingInt(i -> isRunning[i] ? 0 : 1).thenComparing(i -> groups.get(i).get(0)));
            int[] rank = new int[g];
            for (int k = 0; k < g; k++) {
                rank[byKey[k]] = k;
            }
            PriorityQueue<Integer> ready = new PriorityQueue<>((x, y) -> Integer.compare(rank[x], rank[y]));
            for (int i = 0; i < g; i++) {
                pending[i] = providersOfGroup.get(i).size();
                if (pending[i] == 0) {
                    ready.add(i);
                }
            }
            while (!ready.isEmpty()) {
                int i = ready.poll();
                if (trace != null) {
                    step = trace.beginStep(eff[i], isRunning[i], groups.get(i), memUsed, netUsed);
                    for (Cpu cpu : cpus.values()) {
                        cpu.step = step.index();
                    }
                    for (String n : groups.get(i)) {
                        Contract c = cands.get(n);
                        traced.put(n, trace.member(step, n, c.resources().memoryBytes(), c.resources().networkBps()));
                    }
                }
                admitGroup(groups.get(i));
                for (int c : consumersOf.get(i)) {
                    if (--pending[c] == 0) {
                        ready.add(c);
                    }
                }
            }
            AdmissionResult r = result();
            if (trace != null) {
                trace.finish(r);
            }
            return r;
        }

        void admitGroup(List<String> members) {
            // A required provider outside the group that is not admitted refuses the group.
            for (String n : members) {
                List<Wire> ws = requiredIn.getOrDefault(n, List.of());
                for (Wire w : ws) {
                    if (members.contains(w.provider())) {
                        continue;
                    }
                    if (!cands.containsKey(w.provider())) {
                        refuseAll(members, n, "input '" + w.inPort() + "' of '" + n + "': provider '" + w.provider()
                                + "' is not a candidate");
                        return;
                    }
                    if (!admitted.contains(w.provider())) {
                        refuseAll(members, n, "input '" + w.inPort() + "' of '" + n + "': provider '" + w.provider()
                                + "' was refused admission");
                        return;
                    }
                }
            }
            List<Runnable> undo = new ArrayList<>();
            for (String n : members) {
                String refusal = place(cands.get(n), undo);
                if (refusal != null) {
                    for (int k = undo.size() - 1; k >= 0; k--) {
                        undo.get(k).run();
                    }
                    for (String m : members) {
                        AdmissionTrace.Member tm = traced.get(m);
                        if (tm != null) {
                            tm.cpu = -1;
                            tm.prevFirst = false;
                        }
                    }
                    refuseAll(members, n, refusal);
                    return;
                }
            }
        }

        void refuseAll(List<String> members, String culprit, String reason) {
            for (String n : members) {
                if (isExclusive(cands.get(n))) {
                    for (int id : new TreeSet<>(cands.get(n).timing().cpus())) {
                        wantedExclusively.computeIfPresent(id, (k, v) -> v > 1 ? v - 1 : null);
                    }
                }
                String r = n.equals(culprit) ? reason
                        : "refused with its cycle " + members + ": '" + culprit + "': " + reason;
                decisions.put(n, new Decision(n, false, OptionalInt.empty(), wcetOf(cands.get(n)), -1, r));
            }
        }

        /** Notes a measured WCET larger than the declared one. */
        void noteMeasured(Contract c) {
            long wcet = wcetOf(c);
            long declared = c.timing().wcetNs();
            if (wcet > declared) {
                notes.put(c.name(), "measured WCET " + Text.duration(wcet) + " > declared " + Text.duration(declared));
            }
        }

        long wcetOf(Contract c) {
            if (c.taskType() == Contract.TaskType.SERVICE) {
                return 0;
            }
            long m = measured.getOrDefault(c.name(), 0L);
            return Math.max(c.timing().wcetNs(), m);
        }

        /** Places one component; returns null on success (with undo steps added) or the refusal. */
        String place(Contract c, List<Runnable> undo) {
            String n = c.name();
            long mem = c.resources().memoryBytes();
            long net = c.resources().networkBps();
            AdmissionTrace.Member tm = traced.get(n);
            if (tm != null) {
                tm.budgetChecked = true;
                tm.memBefore = memUsed;
                tm.netBefore = netUsed;
                tm.budgetRefused = memUsed + mem > caps.memoryBytes() || netUsed + net > caps.networkBps();
            }
            if (memUsed + mem > caps.memoryBytes()) {
                return "memory: " + Text.bytes(mem) + " requested, " + Text.bytes(Math.max(0, caps.memoryBytes() - memUsed))
                        + " free";
            }
            if (netUsed + net > caps.networkBps()) {
                return "network: " + Text.rate(net) + " requested, " + Text.rate(Math.max(0, caps.networkBps() - netUsed))
                        + " free";
            }
            Cpu chosen = null;
            if (c.taskType() != Contract.TaskType.SERVICE) {
                Timing t = c.timing();
                long wcet = wcetOf(c);
                long declared = t.wcetNs();
                noteMeasured(c);
                if (t.periodNs() <= 0) {
                    return "timing: period " + t.periodNs() + " ns is not positive";
                }
                if (t.deadlineNs() <= 0 || t.deadlineNs() > t.periodNs()) {
                    return "timing: deadline " + Text.duration(t.deadlineNs()) + " is not in (0, period "
                            + Text.duration(t.periodNs()) + "]";
                }
                Task task;
                try {
                    task = new Task(n, t.periodNs(), t.deadlineNs(), wcet, t.priority());
                } catch (IllegalArgumentException e) {
                    return "timing: " + e.getMessage() + (wcet > declared ? " (" + notes.get(n) + ")" : "");
                }
                if (wcet > t.deadlineNs()) {
                    return "timing: WCET " + Text.duration(wcet) + " exceeds deadline " + Text.duration(t.deadlineNs())
                            + (wcet > declared ? " (" + notes.get(n) + ")" : "");
                }
                List<Cpu> allowed = new ArrayList<>();
                if (t.cpus().isEmpty()) {
                    for (Cpu cpu : cpus.values()) {
                        if (!cpu.reserved) {
                            allowed.add(cpu);
                        }
                    }
                    if (allowed.isEmpty() && !cpus.isEmpty()) {
                        return "cpu: every capacity cpu is reserved (" + join(cpus.keySet())
                                + ") and the contract names none in timing/@cpus";
                    }
                } else {
                    for (int id : new TreeSet<>(t.cpus())) {
                        Cpu cpu = cpus.get(id);
                        if (cpu != null) {
                            allowed.add(cpu);
                        }
                    }
                }
                if (allowed.isEmpty()) {
                    return "cpu: " + (t.cpus().isEmpty() ? "no cpu in capacities"
                            : "allowed cpus " + join(new TreeSet<>(t.cpus())) + " not in capacities (have "
                                    + (cpus.isEmpty() ? "none" : join(cpus.keySet())) + ")");
                }
                // Keep the previous CPU when it still fits; otherwise worst fit, then lowest id;
                // a shared task tries the CPUs an exclusive candidate still wants last.
                boolean exclusive = t.exclusive();
                if (tm != null) {
                    tm.allowed = new int[allowed.size()];
                    for (int k = 0; k < allowed.size(); k++) {
                        tm.allowed[k] = allowed.get(k).id;
                    }
                }
                List<Cpu> order = new ArrayList<>(allowed);
                order.sort(Comparator.comparingInt((Cpu x) -> !exclusive && wantedExclusively.containsKey(x.id) ? 1 : 0)
                        .thenComparingDouble(x -> x.util).thenComparingInt(x -> x.id));
                Integer prev = previousCpu.get(n);
                if (prev != null) {
                    for (int k = 0; k < order.size(); k++) {
                        if (order.get(k).id == prev) {
                            order.add(0, order.remove(k));
                            break;
                        }
                    }
                }
                List<String> why = new ArrayList<>();
                for (Cpu cpu : order) {
                    String excl = cpu.exclusion(task, exclusive);
                    if (excl != null) {
                        why.add(excl);
                        continue;
                    }
                    String no = cpu.test(task);
                    if (no == null) {
                        chosen = cpu;
                        break;
                    }
                    why.add(no);
                }
                if (chosen == null) {
                    String r = why.size() <= 3 ? String.join("; ", why)
                            : String.join("; ", why.subList(0, 3)) + "; and " + (why.size() - 3) + " more cpus";
                    return wcet > declared ? r + " (" + notes.get(n) + ")" : r;
                }
                Cpu cpu = chosen;
                if (tm != null) {
                    tm.cpu = cpu.id;
                    tm.prevFirst = prev != null && order.get(0) == cpu && cpu.id == prev;
                }
                Runnable cpuUndo = cpu.add(task);
                placedOn.put(n, cpu);
                taskOf.put(n, task);
                if (exclusive) {
                    cpu.owner = n;
                    for (int id : new TreeSet<>(t.cpus())) {
                        wantedExclusively.computeIfPresent(id, (k, v) -> v > 1 ? v - 1 : null);
                    }
                }
                undo.add(() -> {
                    if (exclusive) {
                        cpu.owner = null;
                        for (int id : new TreeSet<>(t.cpus())) {
                            wantedExclusively.merge(id, 1, Integer::sum);
                        }
                    }
                    cpuUndo.run();
                    placedOn.remove(n);
                    taskOf.remove(n);
                });
            }
            memUsed += mem;
            netUsed += net;
            admitted.add(n);
            undo.add(() -> {
                memUsed -= mem;
                netUsed -= net;
                admitted.remove(n);
            });
            return null;
        }

        AdmissionResult result() {
            List<CpuLoad> loads = new ArrayList<>();
            for (Cpu cpu : cpus.values()) {
                loads.add(load(cpu));
            }
            for (String n : admitted) {
                decisions.put(n, admittedDecision(n, cands.get(n)));
            }
            return new AdmissionResult(decisions, loads, memUsed, netUsed, caps);
        }

        /** The load of one CPU as the run leaves it. */
        static CpuLoad load(Cpu cpu) {
            List<Task> sorted = new ArrayList<>(cpu.tasks);
            sorted.sort(Comparator.comparingInt((Task t) -> -t.priority()).thenComparing(Task::name));
            List<String> names = new ArrayList<>();
            for (Task t : sorted) {
                names.add(t.name());
            }
            return new CpuLoad(cpu.id, cpu.cap, cpu.util, names, cpu.analysis().proof());
        }

        /** The decision for an admitted component, once every task is placed. */
        Decision admittedDecision(String n, Contract c) {
            Cpu cpu = placedOn.get(n);
            String reason;
            long r = -1;
            if (cpu == null) {
                reason = "service task: no CPU budget";
            } else {
                Task task = taskOf.get(n);
                r = cpu.analysis().responseTimeNs(n);
                String where = "cpu " + cpu.id + (n.equals(cpu.owner) ? " (exclusive)" : "");
                reason = r >= 0
                        ? where + ": R=" + Text.duration(r) + " <= D=" + Text.duration(task.deadlineNs())
                                + " (U=" + Text.util(cpu.util) + ")"
                        : where + ": " + cpu.analysis().proof() + " holds (U=" + Text.util(cpu.util) + ")";
                if (notes.containsKey(n)) {
                    reason += "; " + notes.get(n);
                }
            }
            return new Decision(n, true, cpu == null ? OptionalInt.empty() : OptionalInt.of(cpu.id), wcetOf(c), r,
                    reason);
        }
    }

    /**
     * A CPU rebuilt from a trace refused a task it had accepted in the recorded run: the test
     * does not keep the contract of {@link CpuAdmissionTest} (its state depends on more than the
     * adds), so nothing can be derived from the trace.
     */
    static final class ReplayRefused extends RuntimeException {
        private static final long serialVersionUID = 1L;

        ReplayRefused(String message) {
            super(message);
        }
    }

    /**
     * Admission resumed just before a step of a recorded run, to place one more component there
     * as a full run over the same candidates plus that one would (see {@link InstallDryRun}, which
     * checks that the run would otherwise be the same). CPUs are rebuilt from the trace; the
     * test's state of a CPU only when it is asked.
     */
    static final class Resumed {
        private final Run run;
        private final String name;

        /**
         * @param trace     the recorded run (no exclusive candidate)
         * @param step      index of the step the new component goes before
         * @param x         the new component
         * @param providers contracts of its required providers (candidates of the recorded run)
         * @param xWires    its input wires
         */
        Resumed(AdmissionTrace trace, int step, Contract x, List<Contract> providers, Collection<Wire> xWires,
                Capacities caps, Map<String, Long> measured, CpuAdmissionTest test) {
            List<Contract> cs = new ArrayList<>(providers);
            cs.add(x);
            this.name = x.name();
            this.run = new Run(cs, xWires, caps, measured, Map.of(), Set.of(), test, null);
            for (Capacities.Cpu c : caps.cpus()) {
                List<Task> before = new ArrayList<>();
                for (AdmissionTrace.Add a : trace.adds(c.id())) {
                    if (a.step() < step) {
                        before.add(a.task());
                    }
                }
                run.cpus.put(c.id(), new Cpu(c, test, before));
            }
            List<AdmissionTrace.Step> steps = trace.steps();
            run.memUsed = step < steps.size() ? steps.get(step).memBefore() : trace.memUsed();
            run.netUsed = step < steps.size() ? steps.get(step).netBefore() : trace.netUsed();
            for (Contract p : providers) {
                if (trace.result().decisions().get(p.name()).admitted()) {
                    run.admitted.add(p.name());
                }
            }
        }

        /** Admits the new component; its decision when refused, else null (see {@link #decision}). */
        Decision admit() {
            run.admitGroup(List.of(name));
            return run.decisions.get(name);
        }

        /** The CPU the new component was placed on, -1 for none. */
        int cpu() {
            Cpu c = run.placedOn.get(name);
            return c == null ? -1 : c.id;
        }

        /** Budgets the new component takes, once admitted. */
        long mem() {
            return run.cands.get(name).resources().memoryBytes();
        }

        long net() {
            return run.cands.get(name).resources().networkBps();
        }

        /** Registers the tasks that were on {@code cpu} before the new component (for their decisions). */
        void adopt(int cpu, Function<String, Contract> contracts) {
            Cpu c = run.cpus.get(cpu);
            for (Task t : c.tasks) {
                if (!t.name().equals(name)) {
                    Contract k = contracts.apply(t.name());
                    run.cands.putIfAbsent(t.name(), k);
                    run.placedOn.put(t.name(), c);
                    run.taskOf.put(t.name(), t);
                    run.noteMeasured(k);
                }
            }
        }

        /**
         * Places a component that the recorded run placed first try on its previous CPU
         * {@code cpu}, now beside the new one: true when it still fits there (then added), false
         * when the full run would go elsewhere.
         */
        boolean keeps(Contract y, int cpu) {
            Cpu c = run.cpus.get(cpu);
            Timing t = y.timing();
            Task task = new Task(y.name(), t.periodNs(), t.deadlineNs(), run.wcetOf(y), t.priority());
            if (c.exclusion(task, t.exclusive()) != null || c.test(task) != null) {
                return false;
            }
            c.add(task);
            run.cands.putIfAbsent(y.name(), y);
            run.placedOn.put(y.name(), c);
            run.taskOf.put(y.name(), task);
            run.noteMeasured(y);
            return true;
        }

        /** Decision of the new component once admitted and every later task is placed. */
        Decision decision() {
            return run.admittedDecision(name, run.cands.get(name));
        }

        /**
         * Decisions of every task on that CPU: {@code known} gives the ones the caller can prove
         * unchanged (null: judge it again).
         */
        List<Decision> decisionsOn(int cpu, Function<Task, Decision> known) {
            List<Decision> out = new ArrayList<>();
            for (Task t : run.cpus.get(cpu).tasks) {
                Decision d = t.name().equals(name) ? null : known.apply(t);
                out.add(d != null ? d : run.admittedDecision(t.name(), run.cands.get(t.name())));
            }
            return out;
        }

        CpuLoad load(int cpu) {
            return Run.load(run.cpus.get(cpu));
        }
    }

    private static String join(Collection<Integer> ids) {
        List<String> s = new ArrayList<>();
        for (int i : ids) {
            s.add(Integer.toString(i));
        }
        return String.join(", ", s);
    }
}
