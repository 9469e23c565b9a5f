package org.arflex.contract;

import java.util.List;

/**
 * Non-functional timing of a component.
 *
 * @param periodNs   period (periodic) or minimum inter-arrival time (sporadic), nanoseconds
 * @param deadlineNs relative deadline, {@code 0 < deadline <= period}
 * @param wcetNs     declared worst-case execution time per release, {@code 0 < wcet <= deadline}
 * @param priority   SCHED_FIFO priority, 1..98 (larger is more urgent, as Linux)
 * @param cpus       CPUs the task may run on; empty means any, admission then picks one
 * @param exclusive  the task keeps the CPU admission gives it to itself: it is only placed on a
 *                   CPU no other real-time task holds, and no other real-time task is placed
 *                   there afterwards (SPEC §8.6); always {@code false} for service tasks
 */
public record Timing(long periodNs, long deadlineNs, long wcetNs, int priority, List<Integer> cpus,
        boolean exclusive) {
    public Timing {
        cpus = List.copyOf(cpus);
    }

    /** Timing that shares its CPU (not {@link #exclusive()}), as before §8.6 existed. */
    public Timing(long periodNs, long deadlineNs, long wcetNs, int priority, List<Integer> cpus) {
        this(periodNs, deadlineNs, wcetNs, priority, cpus, false);
    }

    /** Utilisation {@code wcet / period}. */
    public double utilisation() {
        return (double) wcetNs / periodNs;
    }
}
