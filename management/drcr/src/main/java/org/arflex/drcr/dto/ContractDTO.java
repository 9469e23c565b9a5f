package org.arflex.drcr.dto;

/** A component contract as the DRCR read it. */
public class ContractDTO {
    /** Component name. */
    public String name;
    /** Component version. */
    public String version;
    /** Free text. */
    public String description;
    /** Executable name inside the bundle. */
    public String executable;
    /** PERIODIC, SPORADIC or SERVICE. */
    public String taskType;
    /** True when the component commands motion. */
    public boolean movesHardware;
    /** Period in nanoseconds. */
    public long periodNs;
    /** Relative deadline in nanoseconds. */
    public long deadlineNs;
    /** Declared worst-case execution time in nanoseconds. */
    public long wcetNs;
    /** SCHED_FIFO priority. */
    public int priority;
    /** Allowed CPUs, empty for any. */
    public int[] cpus;
    /** Memory budget in bytes. */
    public long memoryBytes;
    /** Network budget in bytes per second. */
    public long networkBps;
    /** Criticality, larger is more critical. */
    public int criticality;
    /** PERMANENT, TRANSIENT or TEMPORARY. */
    public String restart;
    /** Restarts allowed within the window. */
    public int intensity;
    /** Intensity window in milliseconds. */
    public long windowMs;
    /** First restart delay in milliseconds. */
    public long backoffMs;
    /** HOLD or ZERO. */
    public String safeOutput;
    /** Update URL, or null. */
    public String updateUrl;
    /** Pinned SHA-256 of the update, or null. */
    public String updateSha256;
    /** Where the contract was read from. */
    public String source;
    /** Id of the bundle that carries the contract. */
    public long bundleId;
    /** The ports in declaration order. */
    public PortDTO[] ports;
}
