package org.arflex.planner.impl;

import java.util.ArrayList;
import java.util.Collection;
import java.util.Comparator;
import java.util.List;
import org.arflex.planner.CpuAdmissionTest.Task;

/**
 * Uniprocessor fixed-priority schedulability tests used by {@link ResponseTimeTest}, public so they
 * can be checked against textbook examples.
 *
 * <p>Tasks are periodic or sporadic (period = minimum inter-arrival time) with constrained
 * deadlines ({@code D <= T}), independent, fully preemptive (SCHED_FIFO). Tasks of equal
 * priority are counted as interfering with each other (FIFO order among equals is not known in
 * advance), which is safe.
 */
public final class Schedulability {

    private Schedulability() {
    }

    /** Total utilisation {@code sum C/T}. */
    public static double utilisation(Collection<Task> tasks) {
        double u = 0;
        for (Task t : tasks) {
            u += t.utilisation();
        }
        return u;
    }

    /** The Liu and Layland bound {@code n (2^(1/n) - 1)} for n tasks (1 for n = 0). */
    public static double liuLaylandBound(int n) {
        return n == 0 ? 1.0 : n * (Math.pow(2.0, 1.0 / n) - 1.0);
    }

    /**
     * True when the bounds apply to this set: every deadline is implicit and priorities are rate
     * monotonic (a shorter period never has a lower or equal priority than a longer one).
     */
    public static boolean boundsApply(Collection<Task> tasks) {
        for (Task t : tasks) {
            if (!t.implicitDeadline()) {
                return false;
            }
        }
        List<Task> sorted = new ArrayList<>(tasks);
        sorted.sort(Comparator.comparingLong(Task::periodNs));
        // Every task must have a strictly higher priority than all tasks of longer period.
        int i = 0;
        int minPrioShorter = Integer.MAX_VALUE;
        while (i < sorted.size()) {
            int j = i;
            int minHere = Integer.MAX_VALUE;
            int maxHere = Integer.MIN_VALUE;
            while (j < sorted.size() && sorted.get(j).periodNs() == sorted.get(i).periodNs()) {
                minHere = Math.min(minHere, sorted.get(j).priority());
                maxHere = Math.max(maxHere, sorted.get(j).priority());
                j++;
            }
            if (maxHere >= minPrioShorter) {
                return false;
            }
            minPrioShorter = Math.min(minPrioShorter, minHere);
            i = j;
        }
        return true;
    }

    /**
     * Liu and Layland's sufficient test: {@code U <= n (2^(1/n) - 1)}. Only meaningful when
     * {@link #boundsApply} holds; returns false otherwise.
     */
    public static boolean liuLaylandTest(Collection<Task> tasks) {
        return boundsApply(tasks) && utilisation(tasks) <= liuLaylandBound(tasks.size()) + 1e-12;
    }

    /**
     * Bini and Buttazzo's hyperbolic sufficient test: {@code prod (U_i + 1) <= 2}, never worse
     * than Liu and Layland's. Only meaningful when {@link #boundsApply} holds; returns false
     * otherwise.
     */
    public static boolean hyperbolicTest(Collection<Task> tasks) {
        if (!boundsApply(tasks)) {
            return false;
        }
        double p = 1;
        for (Task t : tasks) {
            p *= t.utilisation() + 1;
        }
        return p <= 2 + 1e-12;
    }

    /**
     * Exact worst-case response time of {@code task} among {@code others} (Joseph and Pandya;
     * Audsley et al.): the least fixpoint of {@code R = C + sum ceil(R / Tj) Cj} over the other
     * tasks of higher or equal priority, starting from {@code C}. Tasks in {@code others} equal
     * to {@code task} are ignored.
     *
     * @return the response time in ns, or {@code -1} when it exceeds the task's deadline (the
     *         iteration stops there)
     */
    public static long responseTime(Task task, Collection<Task> others) {
        return responseTime(task, others, task.wcetNs());
    }

    /**
     * As {@link #responseTime(Task, Collection)}, starting the iteration from {@code start}
     * (any value not above the true response time, for example a previous result before a task
     * was added; values below C are raised to C).
     */
    public static long responseTime(Task task, Collection<Task> others, long start) {
        long r = Math.max(start, task.wcetNs());
        while (true) {
            long next = task.wcetNs();
            for (Task o : others) {
                if (o == task || o.priority() < task.priority() || (o.name().equals(task.name()) && o.equals(task))) {
                    continue;
                }
                long releases = (r + o.periodNs() - 1) / o.periodNs();
                next += releases * o.wcetNs();
                if (next > task.deadlineNs()) {
                    return -1;
                }
            }
            if (next == r) {
                return r;
            }
            r = next;
        }
    }

    /** True when every task meets its deadline by {@link #responseTime}. */
    public static boolean rtaTest(Collection<Task> tasks) {
        for (Task t : tasks) {
            if (responseTime(t, tasks) < 0) {
                return false;
            }
        }
        return true;
    }
}
