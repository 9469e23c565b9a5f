package org.arflex.planner;

import org.arflex.planner.impl.ResponseTimeTest;

/**
 * The schedulability test admission runs on each CPU: whether one more task fits beside the
 * tasks already placed there.
 *
 * <p>Admission keeps everything else: the order of the components, which CPUs a task may use
 * (allowed, reserved, exclusive), the utilisation cap of each CPU (checked before the test is
 * asked), memory and network budgets, and the undoing of a cycle refused as a whole. For every
 * admission run it {@link #open opens} one {@link Cpu} per capacity CPU and then calls
 * {@link Cpu#test} and {@link Cpu#add} as it places tasks, from one thread.
 *
 * <p>The default, {@link #responseTime()}, is what {@link Planner#Planner(Capacities)} uses.
 */
public interface CpuAdmissionTest {

    /**
     * Fixed-priority preemptive scheduling, equal priorities interfering both ways: the
     * hyperbolic bound when every deadline is implicit and priorities are rate monotonic, else
     * exact response-time analysis of the new task and of every task it can delay.
     */
    static CpuAdmissionTest responseTime() {
        return new ResponseTimeTest();
    }

    /**
     * An empty CPU, for one admission run.
     *
     * @param cpu the Linux CPU number
     */
    Cpu open(int cpu);

    /** The analysis of one CPU during one admission run. */
    interface Cpu {

        /**
         * Whether {@code task} fits beside the tasks added so far; does not change the state.
         *
         * @return null when it fits, else why not in one sentence with the numbers (admission
         *         prefixes it with {@code "cpu N: "})
         */
        String test(Task task);

        /**
         * Adds a task that passed {@link #test} just before.
         *
         * @return the step that takes it off again (admission runs such steps last added first)
         */
        Runnable add(Task task);

        /**
         * What proves the tasks added so far schedulable, shown in {@link CpuLoad#test()}:
         * {@code "none"} when there are none.
         */
        String proof();

        /**
         * The worst-case response time of an added task, ns, or -1 when the proof needs none
         * (a utilisation bound). Asked once all tasks are placed.
         */
        long responseTimeNs(String task);
    }

    /**
     * One periodic or sporadic task on one CPU.
     *
     * @param name       component name
     * @param periodNs   period or minimum inter-arrival time, {@code > 0}
     * @param deadlineNs relative deadline, {@code 0 < D <= T}
     * @param wcetNs     worst-case execution time used for the analysis, {@code > 0}
     * @param priority   larger is more urgent
     */
    record Task(String name, long periodNs, long deadlineNs, long wcetNs, int priority) {

        /** @throws IllegalArgumentException naming the task when a value is out of range */
        public Task {
            if (periodNs <= 0) {
                throw new IllegalArgumentException("task '" + name + "': period " + periodNs + " ns is not positive");
            }
            if (deadlineNs <= 0 || deadlineNs > periodNs) {
                throw new IllegalArgumentException("task '" + name + "': deadline " + deadlineNs
                        + " ns is not in (0, period " + periodNs + " ns]");
            }
            if (wcetNs <= 0) {
                throw new IllegalArgumentException("task '" + name + "': WCET " + wcetNs + " ns is not positive");
            }
        }

        /** {@code C / T}. */
        public double utilisation() {
            return (double) wcetNs / periodNs;
        }

        /** True when {@code D == T}. */
        public boolean implicitDeadline() {
            return deadlineNs == periodNs;
        }
    }
}
