package org.arflex.drcr.dto;

/** Capacities of the Resource Manager and their use by admitted components. */
public class ResourcesDTO {
    /** CPUs available to RT tasks. */
    public int[] cpus;
    /** Memory capacity in bytes. */
    public long memoryBytes;
    /** Network capacity in bytes per second. */
    public long networkBps;
    /** Memory admitted. */
    public long memoryUsed;
    /** Network admitted. */
    public long networkUsed;
    /** Utilisation admitted per CPU, same order as {@link #cpus}. */
    public double[] cpuUtilisation;
    /** Total measured WCET overruns reported by the RT halves. */
    public long wcetOverruns;
}
