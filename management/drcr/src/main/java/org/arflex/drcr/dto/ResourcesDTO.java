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
    /**
     * What the machine gives the runtime (D85): the CPUs online and in its cpuset, its memory
     * limit and the cgroups they come from; null when it is not observed.
     */
    public String machine;
    /** The cause of the last change of the machine, e.g. {@code cpu 1 left the runtime's cpuset /x (cgroup v1)}. */
    public String machineChange;
    /** Why the machine cannot be read now (the last good view is kept), null when it can. */
    public String machineProblem;
}
