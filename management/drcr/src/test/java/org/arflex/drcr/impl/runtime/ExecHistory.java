package org.arflex.drcr.impl.runtime;

import org.arflex.drcr.impl.abi.ControlBlock;

/**
 * An RT half's execution-time counters as its control block holds them (since its start:
 * count, sum, max and the histogram), built up run by run for a {@link FakeLauncher.FakeHalf}.
 */
final class ExecHistory {
    private final long[] bins = new long[ControlBlock.HIST_BINS + 1];
    private long count;
    private long sum;
    private long max;

    /** {@code n} more executions of {@code ns} each. */
    ExecHistory run(long n, long ns) {
        bins[(int) Math.min(ControlBlock.HIST_BINS, ns / ControlBlock.HIST_BIN_NS)] += n;
        count += n;
        sum += n * ns;
        max = Math.max(max, ns);
        return this;
    }

    /** Puts the counters as they are now into {@code h}, its stats counting those at or above {@code wcetNs}. */
    void into(FakeLauncher.FakeHalf h, long wcetNs) {
        long over = 0;
        for (int b = (int) Math.min(ControlBlock.HIST_BINS, (wcetNs + ControlBlock.HIST_BIN_NS - 1) / ControlBlock.HIST_BIN_NS);
                b <= ControlBlock.HIST_BINS; b++) {
            over += bins[b];
        }
        h.stats = new ControlBlock.Stats(count, 0, 0, 0, 0, max, count, sum, over, 0);
        h.exec = new ControlBlock.Metric(count, 0, max, sum, bins.clone());
    }
}
