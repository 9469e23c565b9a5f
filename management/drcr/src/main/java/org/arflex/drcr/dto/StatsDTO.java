package org.arflex.drcr.dto;

/** RT statistics read from a control block. */
public class StatsDTO {
    /** Completed cycles. */
    public long cycles;
    /** Cycles that missed their deadline. */
    public long overruns;
    /** Cycles whose execution time exceeded the declared WCET. */
    public long wcetOverruns;
    /** Largest release latency observed, nanoseconds. */
    public long maxLatencyNs;
    /** Largest execution time observed, nanoseconds. */
    public long maxExecNs;
    /** Mean execution time, nanoseconds. */
    public long meanExecNs;
    /** RT-half state as the RT half reports it. */
    public String rtState;
    /** Age of the RT half's heartbeat when read, milliseconds. */
    public long heartbeatAgeMs;
}
