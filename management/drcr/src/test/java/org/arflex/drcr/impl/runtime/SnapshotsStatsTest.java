package org.arflex.drcr.impl.runtime;

import static org.junit.jupiter.api.Assertions.assertArrayEquals;
import static org.junit.jupiter.api.Assertions.assertEquals;

import org.arflex.drcr.dto.StatsDTO;
import org.arflex.drcr.impl.abi.ControlBlock;
import org.junit.jupiter.api.Test;

/** The StatsDTO's percentiles and compact latency histogram. */
class SnapshotsStatsTest {

    @Test
    void nonEmptyBinsAsTwoArraysPlusOverflow() {
        long[] lat = new long[ControlBlock.HIST_BINS + 1];
        lat[0] = 5;
        lat[7] = 90;
        lat[1999] = 4;
        lat[ControlBlock.HIST_BINS] = 1;
        long[] ex = new long[ControlBlock.HIST_BINS + 1];
        ex[10] = 100;
        StatsDTO d = new StatsDTO();
        Snapshots.histogram(d, new ControlBlock.Metric(100, 50, 300_000, 0, lat),
                new ControlBlock.Metric(100, 1000, 1090, 0, ex));
        assertEquals(100, d.latencyCount);
        assertEquals(ControlBlock.HIST_BIN_NS, d.histBinNs);
        assertArrayEquals(new int[] {0, 7, 1999}, d.latencyHistBins);
        assertArrayEquals(new long[] {5, 90, 4}, d.latencyHistCounts);
        assertEquals(1, d.latencyHistOverflow);
        assertEquals(800, d.latencyP50Ns);
        assertEquals(200_000, d.latencyP99Ns);
        assertEquals(300_000, d.latencyP999Ns);
        assertEquals(1090, d.execP50Ns);
        assertEquals(1090, d.execP999Ns);
    }
}
