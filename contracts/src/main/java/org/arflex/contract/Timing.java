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
 */
public record Timing(long periodNs, long deadlineNs, long wcetNs, int priority, List<Integer> cpus) {
    public Timing {
        cpus = List.copyOf(cpus);
    }

    /** Utilisation {@code wcet / period}. */
    public double utilisation() {
        return (double) wcetNs / periodNs;
    }
}
