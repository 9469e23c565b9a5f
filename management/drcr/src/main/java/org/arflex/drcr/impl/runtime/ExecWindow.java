package org.arflex.drcr.impl.runtime;

import org.arflex.drcr.impl.abi.ControlBlock;

/**
 * One sampling window of an RT half's execution times: the difference of its execution-time
 * metric between two looks (D82). Its sustained level is the time at least {@code k} of the
 * window's executions reached, k being what makes an exceedance sustained ({@link
 * WcetMonitor#sustainedOverWcet}): an execution a stall of the machine inflated (rt-core's
 * {@code end - wake} includes preemption and a VM's lost CPU) is one of them, so one stall
 * cannot set the level.
 *
 * @param cycles executions in the window
 * @param sumNs  their summed execution time
 * @param bins   the window's histogram (ControlBlock.Metric's bins), or null when the half has none
 */
record ExecWindow(long cycles, long sumNs, long[] bins) {

    /** The window from {@code before} (null: the half's start) to {@code now}. */
    static ExecWindow between(ControlBlock.Metric before, ControlBlock.Metric now) {
        if (now.bins() == null) {
            return new ExecWindow(now.count() - (before == null ? 0 : before.count()),
                    now.sumNs() - (before == null ? 0 : before.sumNs()), null);
        }
        long[] b = now.bins().clone();
        if (before != null && before.bins() != null) {
            for (int i = 0; i < b.length; i++) {
                b[i] -= before.bins()[i];
            }
        }
        return new ExecWindow(now.count() - (before == null ? 0 : before.count()),
                now.sumNs() - (before == null ? 0 : before.sumNs()), b);
    }

    /**
     * The execution time that at least {@code k} executions of the window reached: the upper
     * edge of the histogram bin holding the k-th longest. When it lies in the overflow bin (200
     * us or more, lengths not kept), the mean of the overflow bin's executions, estimated from
     * the window's sum less every shorter execution at its bin's lower edge (so an upper
     * estimate). Without a histogram, the window's mean. 0 for an empty window.
     */
    long levelNs(long k) {
        if (cycles <= 0) {
            return 0;
        }
        if (bins == null) {
            return sumNs / cycles;
        }
        int top = ControlBlock.HIST_BINS;
        long acc = bins[top];
        if (acc >= k) {
            long shorter = 0;
            for (int i = 0; i < top; i++) {
                shorter += bins[i] * (long) i * ControlBlock.HIST_BIN_NS;
            }
            long rangeNs = (long) top * ControlBlock.HIST_BIN_NS;
            return Math.max(rangeNs, (sumNs - shorter) / bins[top]);
        }
        for (int i = top - 1; i >= 0; i--) {
            acc += bins[i];
            if (acc >= k) {
                return (long) (i + 1) * ControlBlock.HIST_BIN_NS;
            }
        }
        return 0;
    }
}
