package org.arflex.drcr.impl.services;

import java.util.ArrayList;
import java.util.List;
import org.arflex.drcr.ResourceManager;
import org.arflex.drcr.dto.ResourcesDTO;
import org.arflex.drcr.impl.runtime.Cell;
import org.arflex.planner.AdmissionResult;
import org.arflex.planner.Capacities;
import org.arflex.planner.CpuLoad;

/**
 * Capacities the planner admits against. Every change goes to the cell, which re-plans (and
 * stops the lowest criticality first when a capacity shrinks).
 */
public final class ResourceManagerImpl implements ResourceManager {

    private final Cell cell;
    private final double utilisationCap;
    private final java.util.Set<Integer> reservedCpus;
    private volatile long wcetOverruns;

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
            return d;
        }, Services.CALL_MS);
    }

    @Override
    public void setCpus(List<Integer> cpus) {
        cell.actor().call(() -> cell.capacities(cell.planner().capacities().withCpus(
                capacities(cpus, 0, 0).cpus())), Services.CALL_MS);
    }

    @Override
    public void setMemory(long bytes) {
        cell.actor().call(() -> cell.capacities(cell.planner().capacities().withMemoryBytes(bytes)), Services.CALL_MS);
    }

    @Override
    public void setNetwork(long bytesPerSecond) {
        cell.actor().call(() -> cell.capacities(cell.planner().capacities().withNetworkBps(bytesPerSecond)),
                Services.CALL_MS);
    }
}
