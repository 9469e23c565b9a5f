package org.arflex.planner.impl;

import java.util.ArrayList;
import java.util.Collection;
import java.util.HashMap;
import java.util.HashSet;
import java.util.List;
import java.util.Map;
import java.util.OptionalInt;
import java.util.PriorityQueue;
import java.util.Set;
import java.util.TreeMap;
import java.util.TreeSet;
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

/** One admission run (see {@link Admission}): the order of the groups, then each group placed or refused as a whole. */
final class AdmissionRun {
    final TreeMap<String, Contract> cands = new TreeMap<>();
    final Map<String, List<Wire>> requiredIn = new HashMap<>();
    final Capacities caps;
    final Map<String, Long> measured;
    final Map<String, Integer> previousCpu;
    final Set<String> running;
    final TreeMap<Integer, AdmissionCpu> cpus = new TreeMap<>();
    final TreeMap<String, Decision> decisions = new TreeMap<>();
    final Map<String, AdmissionCpu> placedOn = new HashMap<>();
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

    AdmissionRun(Collection<Contract> candidates, Collection<Wire> wires, Capacities caps, Map<String, Long> measured,
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
            AdmissionCpu cpu = new AdmissionCpu(c, cpuTest);
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
        AdmissionOrder admissionOrder = new AdmissionOrder(cands, this::providersOf, running);
        List<List<String>> groups = admissionOrder.groups;
        List<Set<Integer>> consumersOf = admissionOrder.consumersOf;
        int[] eff = admissionOrder.eff;
        boolean[] isRunning = admissionOrder.isRunning;
        int[] pending = admissionOrder.pending;
        PriorityQueue<Integer> ready = admissionOrder.ready;
        while (!ready.isEmpty()) {
            int i = ready.poll();
            if (trace != null) {
                step = trace.beginStep(eff[i], isRunning[i], groups.get(i), memUsed, netUsed);
                for (AdmissionCpu cpu : cpus.values()) {
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
        AdmissionCpu chosen = null;
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
            List<AdmissionCpu> allowed = new ArrayList<>();
            String none = CpuCandidates.allowed(t, cpus, allowed);
            if (none != null) {
                return none;
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
            Integer prev = previousCpu.get(n);
            List<AdmissionCpu> order = CpuCandidates.order(allowed, exclusive, wantedExclusively, prev);
            List<String> why = new ArrayList<>();
            for (AdmissionCpu cpu : order) {
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
            AdmissionCpu cpu = chosen;
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
        for (AdmissionCpu cpu : cpus.values()) {
            loads.add(AdmissionCpu.load(cpu));
        }
        for (String n : admitted) {
            decisions.put(n, admittedDecision(n, cands.get(n)));
        }
        return new AdmissionResult(decisions, loads, memUsed, netUsed, caps);
    }


    /** The decision for an admitted component, once every task is placed. */
    Decision admittedDecision(String n, Contract c) {
        AdmissionCpu cpu = placedOn.get(n);
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
