package org.arflex.planner;

import java.util.List;

/**
 * The load admission placed on one CPU.
 *
 * @param cpu            Linux CPU number
 * @param utilisationCap the cap from {@link Capacities.Cpu}
 * @param utilisation    {@code sum C/T} of the tasks placed here (with measured WCETs)
 * @param tasks          the components placed here, by decreasing priority, then name
 * @param test           which test proved the set schedulable: {@code "none"} (empty),
 *                       {@code "hyperbolic bound"} or {@code "response-time analysis"}
 */
public record CpuLoad(int cpu, double utilisationCap, double utilisation, List<String> tasks, String test) {
    public CpuLoad {
        tasks = List.copyOf(tasks);
    }
}
