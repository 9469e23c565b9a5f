package org.arflex.planner.impl;

import java.util.ArrayList;
import java.util.Comparator;
import java.util.List;
import org.arflex.planner.Capacities;
import org.arflex.planner.CpuAdmissionTest;
import org.arflex.planner.CpuAdmissionTest.Task;
import org.arflex.planner.CpuLoad;

/** One capacity CPU during a run: placement state here, schedulability in {@link #analysis}. */
final class AdmissionCpu {
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

    AdmissionCpu(Capacities.Cpu c, CpuAdmissionTest test) {
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
    AdmissionCpu(Capacities.Cpu c, CpuAdmissionTest test, List<Task> placed) {
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

    /** The load of one CPU as the run leaves it. */
    static CpuLoad load(AdmissionCpu cpu) {
        List<Task> sorted = new ArrayList<>(cpu.tasks);
        sorted.sort(Comparator.comparingInt((Task t) -> -t.priority()).thenComparing(Task::name));
        List<String> names = new ArrayList<>();
        for (Task t : sorted) {
            names.add(t.name());
        }
        return new CpuLoad(cpu.id, cpu.cap, cpu.util, names, cpu.analysis().proof());
    }
}
