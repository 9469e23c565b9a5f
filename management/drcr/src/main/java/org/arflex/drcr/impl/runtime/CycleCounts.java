package org.arflex.drcr.impl.runtime;

import org.arflex.drcr.impl.abi.ControlBlock;
import org.arflex.drcr.impl.supervisor.RtHalf;

/**
 * The counters of an update's two halves from a baseline on, for its shadow run (D42) and its
 * rollback window (D38): the new half's cycles since, and each half's late cycles since (an
 * overrun or a deadline miss; one cycle that did both counts once, {@link LateCycles}, D73). Reads both halves' control blocks; a half that is gone reads as null. Actor
 * thread.
 */
final class CycleCounts {
    private final Instance next;
    private final RtHalf nextHalf;
    private final Instance old;
    private final RtHalf oldHalf;
    /** The last cycles seen never go back (the shadow run), or follow the counter (the window). */
    private final boolean neverBack;
    private long cycles0;
    private long lastCycles;
    private long newBad0;
    private long oldBad0;

    CycleCounts(Instance next, RtHalf nextHalf, Instance old, RtHalf oldHalf, boolean neverBack) {
        this.next = next;
        this.nextHalf = nextHalf;
        this.old = old;
        this.oldHalf = oldHalf;
        this.neverBack = neverBack;
    }

    /** Counts from now on. */
    void baseline() {
        ControlBlock.Stats n = newStats();
        ControlBlock.Stats o = oldStats();
        cycles0 = n == null ? 0 : n.cycles();
        newBad0 = LateCycles.of(n, next.contract.taskType());
        oldBad0 = LateCycles.of(o, old.contract.taskType());
    }

    /** The new half's control block now, or null when it is gone or unreadable. */
    ControlBlock.Stats newStats() {
        return stats(nextHalf, next);
    }

    /** The old half's control block now, or null when it is gone or unreadable. */
    ControlBlock.Stats oldStats() {
        return stats(oldHalf, old);
    }

    /** The new half's cycles since the baseline; the last seen once it is gone. */
    long cycles() {
        ControlBlock.Stats n = newStats();
        if (n != null) {
            lastCycles = neverBack ? Math.max(lastCycles, n.cycles() - cycles0) : n.cycles() - cycles0;
        }
        return lastCycles;
    }

    /** The cycles last returned by {@link #cycles()}, without reading. */
    long lastCycles() {
        return lastCycles;
    }

    /** The new half's late cycles since the baseline, from {@code n}. */
    long newBad(ControlBlock.Stats n) {
        return LateCycles.of(n, next.contract.taskType()) - newBad0;
    }

    /** The old half's late cycles since the baseline, from {@code o}. */
    long oldBad(ControlBlock.Stats o) {
        return LateCycles.of(o, old.contract.taskType()) - oldBad0;
    }

    /** Whether the new half had more late cycles than the old one plus {@link ChangeSetExecutor#OVERRUN_ALLOWANCE}. */
    static boolean beyondAllowance(long newBad, long oldBad) {
        return newBad > oldBad + ChangeSetExecutor.OVERRUN_ALLOWANCE;
    }

    static ControlBlock.Stats stats(RtHalf half, Instance inst) {
        try {
            return half.exit().isDone() ? null : half.stats(inst.contract.timing().wcetNs());
        } catch (RuntimeException e) {
            return null;
        }
    }
}
