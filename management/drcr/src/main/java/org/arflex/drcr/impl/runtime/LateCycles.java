package org.arflex.drcr.impl.runtime;

import org.arflex.contract.Contract;
import org.arflex.drcr.impl.abi.ControlBlock;

/**
 * How many of a half's cycles ended late, from its counters (D73). rt-core counts a periodic
 * cycle that ended after its deadline as a deadline miss, and one that ended after the next
 * release as an overrun; a deadline is at most the period (rt-core refuses more), so every
 * overrun is a deadline miss of the same cycle too, and with deadline = period (every 1 ms
 * loop of the cell) each late cycle is in both counters. It is one late cycle: the larger of
 * the two. A sporadic half's overruns are coalesced input events, not late ends: both count, as
 * before. Used by the shadow run's and the rollback window's comparison of two halves
 * ({@link CycleCounts}).
 */
final class LateCycles {

    private LateCycles() {
    }

    /** The late cycles in {@code s} of a half of {@code type}; 0 for none (a half gone). */
    static long of(ControlBlock.Stats s, Contract.TaskType type) {
        if (s == null) {
            return 0;
        }
        return type == Contract.TaskType.SPORADIC ? s.overruns() + s.deadlineMisses()
                : Math.max(s.overruns(), s.deadlineMisses());
    }
}
