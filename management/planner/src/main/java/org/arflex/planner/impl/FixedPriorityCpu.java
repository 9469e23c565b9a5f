package org.arflex.planner.impl;

import java.util.ArrayList;
import java.util.Comparator;
import java.util.HashMap;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import java.util.TreeMap;
import org.arflex.planner.CpuAdmissionTest;
import org.arflex.planner.CpuAdmissionTest.Task;

/**
 * One CPU under {@link ResponseTimeTest}. A task fits when the hyperbolic bound holds (only when
 * all deadlines are implicit and priorities rate monotonic) or exact response-time analysis
 * passes for the new task and for every task it can delay (lower or equal priority). The bound's
 * product, the rate-monotonic check and each task's processor demand at its deadline are kept up
 * to date in O(1) or O(log n) per task added, so that exact analysis runs only for the tasks
 * whose demand exceeds their deadline.
 */
final class FixedPriorityCpu implements CpuAdmissionTest.Cpu {

    /** One task placed here. */
    private static final class Entry {
        final Task task;
        /** A lower bound of the response time (exact after a test); -1 unknown. */
        long r = -1;
        /**
         * Processor demand in a window of length D: {@code C + sum ceil(D/Tj) Cj} over the other
         * tasks of higher or equal priority here. When it is at most D the response time is at
         * most D (the iteration cannot pass a point where demand fits).
         */
        long demand;

        Entry(Task task) {
            this.task = task;
        }
    }

    /** Response times found by the last {@link #test}, for the task it accepted. */
    private record Accepted(Task task, Map<Entry, Long> newR) {
    }

    private final Map<String, Entry> tasks = new LinkedHashMap<>();
    private double util;
    /** All deadlines implicit and priorities rate monotonic (so the bounds apply). */
    private boolean rmOk = true;
    /** prod (U_i + 1). */
    private double hyper = 1;
    /** period -> {min priority, max priority} of the tasks of that period. */
    private final TreeMap<Long, int[]> prioByPeriod = new TreeMap<>();
    private Accepted accepted;

    private static long ceilDiv(long a, long b) {
        return (a + b - 1) / b;
    }

    /** Whether the bounds still apply with {@code t} added: O(log n) thanks to monotony. */
    private boolean rmOkWith(Task t) {
        if (!rmOk || !t.implicitDeadline()) {
            return false;
        }
        Map.Entry<Long, int[]> shorter = prioByPeriod.lowerEntry(t.periodNs());
        if (shorter != null && shorter.getValue()[0] <= t.priority()) {
            return false;
        }
        Map.Entry<Long, int[]> longer = prioByPeriod.higherEntry(t.periodNs());
        return longer == null || longer.getValue()[1] < t.priority();
    }

    @Override
    public String test(Task t) {
        accepted = null;
        double u = util + t.utilisation();
        if (rmOkWith(t) && hyper * (t.utilisation() + 1) <= 2 + 1e-12) {
            accepted = new Accepted(t, Map.of());
            return null;
        }
        // Only tasks whose processor demand in their deadline window exceeds the deadline need
        // exact analysis: the new task, and those it delays (lower or equal priority).
        Entry fresh = new Entry(t);
        long d0 = t.wcetNs();
        List<Entry> tight = new ArrayList<>();
        for (Entry e : tasks.values()) {
            if (e.task.priority() >= t.priority()) {
                d0 += ceilDiv(t.deadlineNs(), e.task.periodNs()) * e.task.wcetNs();
            }
            if (e.task.priority() <= t.priority()
                    && e.demand + ceilDiv(e.task.deadlineNs(), t.periodNs()) * t.wcetNs() > e.task.deadlineNs()) {
                tight.add(e);
            }
        }
        // Most urgent first, so the first miss reported is the most telling one.
        tight.sort(Comparator.comparingInt((Entry e) -> -e.task.priority()).thenComparing(e -> e.task.name()));
        if (d0 > t.deadlineNs()) {
            tight.add(0, fresh);
        }
        List<Task> all = null;
        Map<Entry, Long> newR = new HashMap<>();
        for (Entry e : tight) {
            if (all == null) {
                all = taskList(t);
            }
            long start = Math.max(e.r, e.task.wcetNs());
            long r = Schedulability.responseTime(e.task, all, start);
            if (r < 0) {
                return miss(t, e == fresh ? null : e.task, all, start, u);
            }
            newR.put(e, r);
        }
        accepted = new Accepted(t, newR);
        return null;
    }

    /** The refusal: {@code victim} (null: {@code t} itself) misses its deadline with {@code t} added. */
    private static String miss(Task t, Task victim, List<Task> all, long start, double u) {
        Task late = victim == null ? t : victim;
        long shown = ResponseTimes.forMessage(late, all, start);
        String rt = shown > 0 ? "response time " + Text.duration(shown) : "response time (unbounded)";
        String who = victim == null ? rt + " of '" + t.name() + "'"
                : "adding '" + t.name() + "' gives " + rt + " of '" + victim.name() + "', which";
        return who + " exceeds deadline " + Text.duration(late.deadlineNs()) + " (U=" + Text.util(u) + ")";
    }

    private List<Task> taskList(Task extra) {
        List<Task> all = new ArrayList<>(tasks.size() + 1);
        for (Entry e : tasks.values()) {
            all.add(e.task);
        }
        all.add(extra);
        return all;
    }

    @Override
    public Runnable add(Task t) {
        if (tasks.containsKey(t.name())) {
            throw new IllegalArgumentException("task '" + t.name() + "' is already on this cpu");
        }
        Entry e = new Entry(t);
        Map<Entry, Long> oldR = new HashMap<>();
        if (accepted != null && accepted.task() == t) {
            for (Map.Entry<Entry, Long> nr : accepted.newR().entrySet()) {
                Entry x = nr.getKey();
                if (x.task == t) {
                    e.r = nr.getValue();
                } else {
                    oldR.put(x, x.r);
                    x.r = nr.getValue();
                }
            }
        }
        accepted = null;
        boolean oldRm = rmOk;
        double oldHyper = hyper;
        double oldUtil = util;
        int[] oldPrio = prioByPeriod.get(t.periodNs());
        rmOk = rmOkWith(t);
        hyper *= t.utilisation() + 1;
        util += t.utilisation();
        prioByPeriod.put(t.periodNs(), oldPrio == null ? new int[] {t.priority(), t.priority()}
                : new int[] {Math.min(oldPrio[0], t.priority()), Math.max(oldPrio[1], t.priority())});
        long d = t.wcetNs();
        List<Entry> delayed = new ArrayList<>();
        for (Entry x : tasks.values()) {
            if (x.task.priority() >= t.priority()) {
                d += ceilDiv(t.deadlineNs(), x.task.periodNs()) * x.task.wcetNs();
            }
            if (x.task.priority() <= t.priority()) {
                x.demand += ceilDiv(x.task.deadlineNs(), t.periodNs()) * t.wcetNs();
                delayed.add(x);
            }
        }
        e.demand = d;
        tasks.put(t.name(), e);
        return () -> {
            for (Entry x : delayed) {
                x.demand -= ceilDiv(x.task.deadlineNs(), t.periodNs()) * t.wcetNs();
            }
            tasks.remove(t.name());
            rmOk = oldRm;
            hyper = oldHyper;
            util = oldUtil;
            if (oldPrio == null) {
                prioByPeriod.remove(t.periodNs());
            } else {
                prioByPeriod.put(t.periodNs(), oldPrio);
            }
            oldR.forEach((x, r) -> x.r = r);
            accepted = null;
        };
    }

    @Override
    public String proof() {
        if (tasks.isEmpty()) {
            return "none";
        }
        return rmOk && hyper <= 2 + 1e-12 ? ResponseTimeTest.HYPERBOLIC : ResponseTimeTest.RTA;
    }

    @Override
    public long responseTimeNs(String name) {
        Entry e = tasks.get(name);
        if (e == null) {
            throw new IllegalArgumentException("task '" + name + "' is not on this cpu");
        }
        if (!proof().equals(ResponseTimeTest.RTA)) {
            return -1;
        }
        List<Task> interfering = new ArrayList<>();
        for (Entry x : tasks.values()) {
            if (x.task.priority() >= e.task.priority()) {
                interfering.add(x.task);
            }
        }
        e.r = Schedulability.responseTime(e.task, interfering, Math.max(e.r, e.task.wcetNs()));
        return e.r;
    }
}
