package org.arflex.planner.impl;

import java.util.ArrayList;
import java.util.Collection;
import java.util.List;
import java.util.Map;
import java.util.Set;
import java.util.function.Function;
import org.arflex.contract.Contract;
import org.arflex.contract.Timing;
import org.arflex.planner.Capacities;
import org.arflex.planner.CpuAdmissionTest;
import org.arflex.planner.CpuAdmissionTest.Task;
import org.arflex.planner.CpuLoad;
import org.arflex.planner.Decision;
import org.arflex.planner.Wire;

/**
 * Admission resumed just before a step of a recorded run, to place one more component there
 * as a full run over the same candidates plus that one would (see {@link InstallDryRun}, which
 * checks that the run would otherwise be the same). CPUs are rebuilt from the trace; the
 * test's state of a CPU only when it is asked.
 */
final class ResumedAdmission {
    private final AdmissionRun run;
    private final String name;

    /**
     * @param trace     the recorded run (no exclusive candidate)
     * @param step      index of the step the new component goes before
     * @param x         the new component
     * @param providers contracts of its required providers (candidates of the recorded run)
     * @param xWires    its input wires
     */
    ResumedAdmission(AdmissionTrace trace, int step, Contract x, List<Contract> providers, Collection<Wire> xWires,
            Capacities caps, Map<String, Long> measured, CpuAdmissionTest test) {
        List<Contract> cs = new ArrayList<>(providers);
        cs.add(x);
        this.name = x.name();
        this.run = new AdmissionRun(cs, xWires, caps, measured, Map.of(), Set.of(), test, null);
        for (Capacities.Cpu c : caps.cpus()) {
            List<Task> before = new ArrayList<>();
            for (AdmissionTrace.Add a : trace.adds(c.id())) {
                if (a.step() < step) {
                    before.add(a.task());
                }
            }
            run.cpus.put(c.id(), new AdmissionCpu(c, test, before));
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
        AdmissionCpu c = run.placedOn.get(name);
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
        AdmissionCpu c = run.cpus.get(cpu);
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
        AdmissionCpu c = run.cpus.get(cpu);
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
        return AdmissionCpu.load(run.cpus.get(cpu));
    }
}
