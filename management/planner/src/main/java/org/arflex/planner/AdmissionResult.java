package org.arflex.planner;

import java.util.Collections;
import java.util.List;
import java.util.OptionalInt;
import java.util.SortedMap;
import java.util.SortedSet;
import java.util.TreeMap;
import java.util.TreeSet;

/**
 * The outcome of admission (in {@link Plan#admission()}): a decision for every candidate, the load of every CPU
 * and the budgets used.
 *
 * @param decisions       one decision per candidate component, by name
 * @param cpus            one entry per capacity CPU, by id
 * @param memoryUsedBytes sum of the admitted components' memory budgets
 * @param networkUsedBps  sum of the admitted components' network budgets
 * @param capacities      the capacities admission ran against
 */
public record AdmissionResult(SortedMap<String, Decision> decisions, List<CpuLoad> cpus, long memoryUsedBytes,
        long networkUsedBps, Capacities capacities) {

    public AdmissionResult {
        decisions = Collections.unmodifiableSortedMap(new TreeMap<>(decisions));
        cpus = List.copyOf(cpus);
    }

    /** Names of the admitted components. */
    public SortedSet<String> admitted() {
        TreeSet<String> s = new TreeSet<>();
        decisions.values().forEach(d -> {
            if (d.admitted()) {
                s.add(d.component());
            }
        });
        return Collections.unmodifiableSortedSet(s);
    }

    /** Refused components and why. */
    public SortedMap<String, String> refused() {
        TreeMap<String, String> m = new TreeMap<>();
        decisions.values().forEach(d -> {
            if (!d.admitted()) {
                m.put(d.component(), d.reason());
            }
        });
        return Collections.unmodifiableSortedMap(m);
    }

    /** CPU of every admitted periodic or sporadic component. */
    public SortedMap<String, Integer> cpuAssignment() {
        TreeMap<String, Integer> m = new TreeMap<>();
        decisions.values().forEach(d -> {
            if (d.admitted() && d.cpu().isPresent()) {
                m.put(d.component(), d.cpu().getAsInt());
            }
        });
        return Collections.unmodifiableSortedMap(m);
    }

    /** The CPU of that component, if it was admitted on one. */
    public OptionalInt cpuOf(String component) {
        Decision d = decisions.get(component);
        return d != null && d.admitted() ? d.cpu() : OptionalInt.empty();
    }
}
