package org.arflex.drcr.impl.abi;

import static org.junit.jupiter.api.Assertions.assertArrayEquals;
import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertNotNull;
import static org.junit.jupiter.api.Assertions.assertNull;

import java.util.List;
import org.junit.jupiter.api.Test;

/** Reading the statistics block with its histograms, from a synthetic control block. */
class ControlBlockStatsTest {

    private final String name = "/arflex.jt" + ProcessHandle.current().pid() + ".hist.ctl";

    private static ControlBlock create(String name) throws Exception {
        return ControlBlock.create(name, new ControlBlock.Config(1_000_000, 0, 0, 0, 0, 0, 0, 0), List.of());
    }

    /** Writes a metric as the RT thread would: count, min, max, sum, histogram. */
    private static void metric(ShmSegment s, int off, long[] bins, long minNs, long maxNs, long sumNs) {
        long count = 0;
        for (int b = 0; b < bins.length; b++) {
            s.putLong(off + ControlBlock.METRIC_HIST + 8 * b, bins[b]);
            count += bins[b];
        }
        s.putLong(off + ControlBlock.METRIC_COUNT, count);
        s.putLong(off + ControlBlock.METRIC_MIN, minNs);
        s.putLong(off + ControlBlock.METRIC_MAX, maxNs);
        s.putLong(off + ControlBlock.METRIC_SUM, sumNs);
    }

    @Test
    void detailCopiesCountersHistogramsAndPercentiles() throws Exception {
        try (ControlBlock cb = create(name)) {
            ShmSegment s = cb.segment();
            ControlBlock.Detail empty = cb.detail(0);
            assertNotNull(empty);
            assertEquals(0, empty.latency().count());
            assertEquals(-1L, empty.latency().minNs(), "min is UINT64_MAX while empty");
            assertEquals(0, empty.latency().percentileNs(50.0));

            // latency: 900 samples in bin 3 ([300,400) ns), 95 in bin 12, 4 in bin 150, 1 overflow
            long[] lat = new long[ControlBlock.HIST_BINS + 1];
            lat[3] = 900;
            lat[12] = 95;
            lat[150] = 4;
            lat[ControlBlock.HIST_BINS] = 1;
            // exec: 1000 samples in bin 20 ([2000,2100) ns), the max is 2050 ns
            long[] ex = new long[ControlBlock.HIST_BINS + 1];
            ex[20] = 1000;
            s.setLongRelease(ControlBlock.OFF_STATS_SEQ, 1); // writer inside
            s.putLong(ControlBlock.OFF_STATS_CYCLES, 1000);
            s.putLong(ControlBlock.OFF_STATS_OVERRUNS, 2);
            s.putLong(ControlBlock.OFF_STATS_UPDATE_ERRORS, 7);
            s.putLong(ControlBlock.OFF_STATS_SAFE_CYCLES, 5);
            metric(s, ControlBlock.OFF_STATS_LATENCY, lat, 310, 250_000, 1_000_000);
            metric(s, ControlBlock.OFF_STATS_EXEC, ex, 2010, 2050, 2_030_000);
            assertNull(cb.detail(0), "an odd seq (writer inside) never yields a copy");
            s.setLongRelease(ControlBlock.OFF_STATS_SEQ, 2);

            ControlBlock.Detail d = cb.detail(2000);
            assertNotNull(d);
            assertEquals(1000, d.stats().cycles());
            assertEquals(2, d.stats().overruns());
            assertEquals(7, d.stats().updateErrors());
            assertEquals(5, d.stats().safeCycles());
            assertEquals(250_000, d.stats().latencyMaxNs());
            assertEquals(1000, d.stats().execOverWcet(), "every exec sample is in a bin at or above the 2000 ns WCET");
            assertEquals(d.stats(), cb.stats(2000), "detail() and stats() agree on the counters");
            assertEquals(1000, d.latency().count());
            assertArrayEquals(lat, d.latency().bins());
            assertEquals(1, d.latency().overflow());
            assertEquals(400, d.latency().percentileNs(50.0), "upper edge of bin 3");
            assertEquals(1300, d.latency().percentileNs(99.0), "990th sample: bin 12");
            assertEquals(15_100, d.latency().percentileNs(99.9), "999th sample: bin 150");
            assertEquals(250_000, d.latency().percentileNs(99.99), "the overflow bin gives the max");
            assertEquals(2050, d.exec().percentileNs(50.0), "the bin edge 2100 is capped at the max 2050");
            assertEquals(2_030_000, d.exec().sumNs());
        }
    }
}
