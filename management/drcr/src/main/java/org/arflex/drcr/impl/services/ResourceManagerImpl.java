package org.arflex.drcr.impl.services;

import java.util.ArrayList;
import java.util.List;
import org.arflex.drcr.ResourceManager;
import org.arflex.drcr.dto.ResourcesDTO;
import org.arflex.drcr.impl.machine.CpuList;
import org.arflex.drcr.impl.machine.MachineView;
import org.arflex.drcr.impl.runtime.Cell;
import org.arflex.planner.AdmissionResult;
import org.arflex.planner.Capacities;
import org.arflex.planner.Change;
import org.arflex.planner.CpuLoad;

/**
 * Capacities the planner admits against. Every change goes to the cell, which re-plans (and
 * stops the lowest criticality first when a capacity shrinks). The capacities are what was asked
 * for (framework properties or the API) within what the machine gives the runtime (D85): the CPUs
 * asked for that are online and in its cpuset (all of those when none were asked for), and the
 * memory asked for up to its cgroup memory limit. A change of the machine re-plans as an API
 * change does, with its cause in the plan and the reasons.
 */
public final class ResourceManagerImpl implements ResourceManager {

    private final Cell cell;
    private final double utilisationCap;
    private final java.util.Set<Integer> reservedCpus;
    private volatile long wcetOverruns;
    /** Asked for, actor thread: the CPUs (null: every CPU the machine gives) and the memory (-1: the planner's). */
    private List<Integer> wantedCpus;
    private long wantedMemory = -1;
    /** What the machine gives, as last applied (null: not observed). */
    private volatile MachineView machine;
    private volatile String machineChange;
    private volatile java.util.function.Supplier<String> machineProblem = () -> null;

    public ResourceManagerImpl(Cell cell, double utilisationCap) {
        this(cell, utilisationCap, java.util.Set.of());
    }

    /**
     * @param reservedCpus CPUs that admission gives only to components naming them in
     *                     {@code timing/@cpus} (framework property {@code arflex.cpus.reserved})
     */
    public ResourceManagerImpl(Cell cell, double utilisationCap, java.util.Set<Integer> reservedCpus) {
        this.cell = cell;
        this.utilisationCap = utilisationCap;
        this.reservedCpus = java.util.Set.copyOf(reservedCpus);
    }

    /**
     * A Resource Manager that keeps the capacities within the machine (D85).
     *
     * @param wantedCpus   the CPUs asked for ({@code arflex.cpus}), null for all the machine gives
     * @param wantedMemory the memory asked for ({@code arflex.memory})
     * @param machine      what the machine gives now, null when it could not be read
     */
    public ResourceManagerImpl(Cell cell, double utilisationCap, java.util.Set<Integer> reservedCpus,
            List<Integer> wantedCpus, long wantedMemory, MachineView machine) {
        this(cell, utilisationCap, reservedCpus);
        this.wantedCpus = wantedCpus == null ? null : List.copyOf(wantedCpus);
        this.wantedMemory = wantedMemory;
        this.machine = machine;
    }

    /** Where the watch says why the machine cannot be read (null: it can). */
    public void machineProblem(java.util.function.Supplier<String> problem) {
        machineProblem = problem;
    }

    /**
     * The capacities for what is asked and what the machine gives (actor thread or before
     * start); {@code fallbackCpus} when neither names CPUs.
     */
    public Capacities effective(List<Integer> fallbackCpus, long fallbackMemory, long network) {
        MachineView m = machine;
        List<Integer> cpus = new ArrayList<>(wantedCpus != null ? wantedCpus
                : m != null ? new ArrayList<>(m.cpus()) : fallbackCpus);
        if (m != null) {
            cpus.retainAll(m.cpus());
        }
        long memory = wantedMemory >= 0 ? wantedMemory : fallbackMemory;
        if (m != null && m.memoryLimit() >= 0) {
            memory = Math.min(memory, m.memoryLimit());
        }
        return capacities(cpus, memory, network);
    }

    /**
     * The machine changed (the watch's thread): the capacities follow and the cell re-plans with
     * the cause, as after an API change.
     */
    public void machine(MachineView now, String cause) {
        cell.actor().call(() -> {
            machine = now;
            machineChange = cause;
            Capacities old = cell.planner().capacities();
            Capacities next = effective(ids(old), old.memoryBytes(), old.networkBps());
            if (!next.equals(old)) {
                cell.apply(Change.capacities(next, cause));
            }
            return null;
        }, Services.CALL_MS);
    }

    private static List<Integer> ids(Capacities c) {
        return c.cpus().stream().map(Capacities.Cpu::id).toList();
    }

    /** Capacities from values (actor thread or before start). */
    public Capacities capacities(List<Integer> cpus, long memory, long network) {
        List<Capacities.Cpu> list = new ArrayList<>();
        for (int c : cpus) {
            list.add(new Capacities.Cpu(c, utilisationCap, reservedCpus.contains(c)));
        }
        return new Capacities(list, memory, network);
    }

    /** Called by the sampler with the total measured WCET overruns. */
    public void overruns(long n) {
        wcetOverruns = n;
    }

    @Override
    public ResourcesDTO resources() {
        return cell.actor().call(() -> {
            AdmissionResult a = cell.planner().current().admission();
            Capacities caps = cell.planner().capacities();
            ResourcesDTO d = new ResourcesDTO();
            d.cpus = caps.cpus().stream().mapToInt(Capacities.Cpu::id).toArray();
            d.cpuUtilisation = new double[d.cpus.length];
            for (CpuLoad l : a.cpus()) {
                for (int k = 0; k < d.cpus.length; k++) {
                    if (d.cpus[k] == l.cpu()) {
                        d.cpuUtilisation[k] = l.utilisation();
                    }
                }
            }
            d.memoryBytes = caps.memoryBytes();
            d.networkBps = caps.networkBps();
            d.memoryUsed = a.memoryUsedBytes();
            d.networkUsed = a.networkUsedBps();
            d.wcetOverruns = wcetOverruns;
            MachineView m = machine;
            d.machine = m == null ? null : m.describe();
            d.machineChange = machineChange;
            d.machineProblem = machineProblem.get();
            return d;
        }, Services.CALL_MS);
    }

    @Override
    public void setCpus(List<Integer> cpus) {
        cell.actor().call(() -> {
            MachineView m = machine;
            if (m != null && !m.cpus().containsAll(cpus)) {
                java.util.TreeSet<Integer> missing = new java.util.TreeSet<>(cpus);
                missing.removeAll(m.cpus());
                throw new IllegalArgumentException("cpus " + CpuList.format(missing) + " not available to the runtime: "
                        + m.describe());
            }
            wantedCpus = List.copyOf(cpus);
            Capacities old = cell.planner().capacities();
            return cell.capacities(effective(ids(old), old.memoryBytes(), old.networkBps()));
        }, Services.CALL_MS);
    }

    @Override
    public void setMemory(long bytes) {
        cell.actor().call(() -> {
            MachineView m = machine;
            if (m != null && m.memoryLimit() >= 0 && bytes > m.memoryLimit()) {
                throw new IllegalArgumentException("memory " + bytes + " bytes is above the runtime's memory limit: "
                        + m.describe());
            }
            wantedMemory = bytes;
            Capacities old = cell.planner().capacities();
            return cell.capacities(effective(ids(old), bytes, old.networkBps()));
        }, Services.CALL_MS);
    }

    @Override
    public void setNetwork(long bytesPerSecond) {
        cell.actor().call(() -> cell.capacities(cell.planner().capacities().withNetworkBps(bytesPerSecond)),
                Services.CALL_MS);
    }
}
