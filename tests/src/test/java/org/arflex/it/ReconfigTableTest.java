package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;

import org.junit.jupiter.api.Test;

/**
 * The p99 column of {@code ./arflex bench reconfig}'s table: a set whose p99 wake-up lay beyond
 * the latency histogram's range printed "null" (a quiet run: one set of 15 with 194 wake-ups later
 * than 200 us); it prints "> 200.0" now, and "-" without wake-ups.
 */
class ReconfigTableTest {

    /** Wake-ups in 100 ns bins: {@code binAndCount} pairs, and {@code overflow} beyond the 2000th bin. */
    private static CellChurnBench.Tally tally(long overflow, int... binAndCount) {
        CellChurnBench.Tally t = new CellChurnBench.Tally();
        t.binNs = 100;
        t.overflow = overflow;
        for (int i = 0; i < binAndCount.length; i += 2) {
            t.hist.put(binAndCount[i], (long) binAndCount[i + 1]);
        }
        return t;
    }

    @Test
    void aP99InsideTheHistogramIsItsBinsUpperEdge() {
        // 995 wake-ups at 10.0-10.1 us, 5 at 20.0-20.1 us: the 990th lies in the first
        assertEquals("10.1", ReconfigBench.p99(tally(0, 100, 995, 200, 5)));
        assertEquals("20.1", ReconfigBench.p99(tally(0, 100, 980, 200, 20)));
    }

    @Test
    void aP99BeyondTheHistogramSaysSoInsteadOfNull() {
        assertEquals("> 200.0", ReconfigBench.p99(tally(194, 100, 1000)));
    }

    @Test
    void noWakeUpsIsADash() {
        assertEquals("-", ReconfigBench.p99(tally(0)));
    }
}
