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
    /**
     * Since 0.5.0: cycles whose update hook returned an error (an input it could not use, a
     * refused reference, a failed write: each component's README says which).
     */
    public long updateErrors;
    /** Since 0.5.0: cycles run through the safe hook (heartbeat lost, reset required). */
    public long safeCycles;
    /**
     * Since 0.7.0: mailbox requests the RT half ignored because they did not carry its token
     * (written into its command queue by another process of this machine: an attack or a bug).
     */
    public long forgedRequests;

    // Since 0.2.0: percentiles and the wake-up latency histogram of the control block (all
    // read under the same seqlock as the counters above). Percentiles are upper bin edges
    // (capped at the max), 0 while there is no sample.

    /** Wake-up latency samples (actual wake minus planned release). */
    public long latencyCount;
    /** Median wake-up latency, nanoseconds. */
    public long latencyP50Ns;
    /** 99th percentile of the wake-up latency, nanoseconds. */
    public long latencyP99Ns;
    /** 99.9th percentile of the wake-up latency, nanoseconds. */
    public long latencyP999Ns;
    /** Median execution time, nanoseconds. */
    public long execP50Ns;
    /** 99th percentile of the execution time, nanoseconds. */
    public long execP99Ns;
    /** 99.9th percentile of the execution time, nanoseconds. */
    public long execP999Ns;
    /** Width of a histogram bin, nanoseconds (bin i covers [i*width, (i+1)*width)). */
    public long histBinNs;
    /**
     * Indices of the non-empty latency bins below the overflow, ascending (lower edge =
     * index * {@link #histBinNs}); null when the RT half gave no histogram.
     */
    public int[] latencyHistBins;
    /** Sample count of each bin in {@link #latencyHistBins}, same order and length. */
    public long[] latencyHistCounts;
    /** Latency samples at or above the histogram's range ({@link #histBinNs} * 2000 ns). */
    public long latencyHistOverflow;
}
