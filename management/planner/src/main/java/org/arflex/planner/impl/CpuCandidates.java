package org.arflex.planner.impl;

import java.util.ArrayList;
import java.util.Collection;
import java.util.Comparator;
import java.util.List;
import java.util.Map;
import java.util.TreeMap;
import java.util.TreeSet;
import org.arflex.contract.Timing;

/**
 * The CPUs one task may be placed on (its {@code timing/@cpus}, else every CPU that is not
 * reserved) and the order admission tries them in.
 */
final class CpuCandidates {
    private CpuCandidates() {
    }

    /** Adds to {@code allowed} the CPUs {@code t} may go to; null, or the refusal when there is none. */
    static String allowed(Timing t, TreeMap<Integer, AdmissionCpu> cpus, List<AdmissionCpu> allowed) {
        if (t.cpus().isEmpty()) {
            for (AdmissionCpu cpu : cpus.values()) {
                if (!cpu.reserved) {
                    allowed.add(cpu);
                }
            }
            if (allowed.isEmpty() && !cpus.isEmpty()) {
                return "cpu: every capacity cpu is reserved (" + join(cpus.keySet())
                        + ") and the contract names none in timing/@cpus";
            }
        } else {
            for (int id : new TreeSet<>(t.cpus())) {
                AdmissionCpu cpu = cpus.get(id);
                if (cpu != null) {
                    allowed.add(cpu);
                }
            }
        }
        if (allowed.isEmpty()) {
            return "cpu: " + (t.cpus().isEmpty() ? "no cpu in capacities"
                    : "allowed cpus " + join(new TreeSet<>(t.cpus())) + " not in capacities (have "
                            + (cpus.isEmpty() ? "none" : join(cpus.keySet())) + ")");
        }
        return null;
    }

    /**
     * The order of trial: worst fit (least utilised), then lowest id; a shared task tries the CPUs
     * an exclusive candidate still wants last; the previous CPU {@code prev} (may be null) first.
     */
    static List<AdmissionCpu> order(List<AdmissionCpu> allowed, boolean exclusive,
            Map<Integer, Integer> wantedExclusively, Integer prev) {
        List<AdmissionCpu> order = new ArrayList<>(allowed);
        order.sort(Comparator.comparingInt((AdmissionCpu x) -> !exclusive && wantedExclusively.containsKey(x.id) ? 1 : 0)
                .thenComparingDouble(x -> x.util).thenComparingInt(x -> x.id));
        if (prev != null) {
            for (int k = 0; k < order.size(); k++) {
                if (order.get(k).id == prev) {
                    order.add(0, order.remove(k));
                    break;
                }
            }
        }
        return order;
    }

    static String join(Collection<Integer> ids) {
        List<String> s = new ArrayList<>();
        for (int i : ids) {
            s.add(Integer.toString(i));
        }
        return String.join(", ", s);
    }
}
