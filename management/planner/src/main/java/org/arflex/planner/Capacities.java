package org.arflex.planner;

import java.util.ArrayList;
import java.util.Comparator;
import java.util.HashSet;
import java.util.List;
import java.util.Optional;

/**
 * What the cell can give real-time components, as the Resource Manager reports it.
 *
 * @param cpus        CPUs available to SCHED_FIFO tasks, sorted by id, ids unique
 * @param memoryBytes lockable memory for all RT halves together
 * @param networkBps  network bandwidth for all components together, bytes per second
 */
public record Capacities(List<Cpu> cpus, long memoryBytes, long networkBps) {

    /**
     * One CPU.
     *
     * @param id             Linux CPU number
     * @param utilisationCap the share of the CPU admission may fill, {@code 0 < cap <= 1}
     *                       (for example 0.9 keeps 10% for the kernel and services)
     * @param reserved       admission places only components that name this CPU in their
     *                       contract's {@code timing/@cpus} here, never one that lets admission
     *                       choose (framework property {@code arflex.cpus.reserved})
     */
    public record Cpu(int id, double utilisationCap, boolean reserved) {
        public Cpu {
            if (id < 0) {
                throw new IllegalArgumentException("cpu id " + id + " is negative");
            }
            if (!(utilisationCap > 0 && utilisationCap <= 1)) {
                throw new IllegalArgumentException("cpu " + id + ": utilisation cap " + utilisationCap
                        + " is not in (0, 1]");
            }
        }

        /** A CPU that is not reserved. */
        public Cpu(int id, double utilisationCap) {
            this(id, utilisationCap, false);
        }
    }

    public Capacities {
        List<Cpu> sorted = new ArrayList<>(cpus);
        sorted.sort(Comparator.comparingInt(Cpu::id));
        HashSet<Integer> seen = new HashSet<>();
        for (Cpu c : sorted) {
            if (!seen.add(c.id())) {
                throw new IllegalArgumentException("cpu " + c.id() + " listed twice in capacities");
            }
        }
        cpus = List.copyOf(sorted);
        if (memoryBytes < 0) {
            throw new IllegalArgumentException("memory capacity " + memoryBytes + " is negative");
        }
        if (networkBps < 0) {
            throw new IllegalArgumentException("network capacity " + networkBps + " is negative");
        }
    }

    /** CPUs {@code 0..count-1}, each with the same cap. */
    public static Capacities of(int cpuCount, double utilisationCap, long memoryBytes, long networkBps) {
        List<Cpu> list = new ArrayList<>();
        for (int i = 0; i < cpuCount; i++) {
            list.add(new Cpu(i, utilisationCap));
        }
        return new Capacities(list, memoryBytes, networkBps);
    }

    /** The CPU of that id, if present. */
    public Optional<Cpu> cpu(int id) {
        return cpus.stream().filter(c -> c.id() == id).findFirst();
    }

    /** A copy with another memory capacity. */
    public Capacities withMemoryBytes(long bytes) {
        return new Capacities(cpus, bytes, networkBps);
    }

    /** A copy with another network capacity. */
    public Capacities withNetworkBps(long bps) {
        return new Capacities(cpus, memoryBytes, bps);
    }

    /**
     * A copy in which exactly the CPUs in {@code ids} are {@link Cpu#reserved() reserved}.
     *
     * @throws IllegalArgumentException when an id is not one of the capacity CPUs
     */
    public Capacities withReserved(java.util.Collection<Integer> ids) {
        HashSet<Integer> have = new HashSet<>();
        cpus.forEach(c -> have.add(c.id()));
        for (int id : ids) {
            if (!have.contains(id)) {
                throw new IllegalArgumentException("reserved cpu " + id + " is not among the capacity cpus " + have);
            }
        }
        List<Cpu> list = new ArrayList<>();
        for (Cpu c : cpus) {
            list.add(new Cpu(c.id(), c.utilisationCap(), ids.contains(c.id())));
        }
        return new Capacities(list, memoryBytes, networkBps);
    }

    /** Ids of the reserved CPUs, ascending. */
    public List<Integer> reservedCpus() {
        return cpus.stream().filter(Cpu::reserved).map(Cpu::id).toList();
    }

    /** A copy with another CPU list. */
    public Capacities withCpus(List<Cpu> newCpus) {
        return new Capacities(newCpus, memoryBytes, networkBps);
    }
}
