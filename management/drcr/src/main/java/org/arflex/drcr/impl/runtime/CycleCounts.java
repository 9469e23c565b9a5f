package org.arflex.drcr.impl.runtime;

import org.arflex.drcr.impl.abi.ControlBlock;
import org.arflex.drcr.impl.supervisor.RtHalf;

/**
 * The counters of an update's two halves from a baseline on, for its shadow run (D42) and its
 * rollback window (D38): the new half's cycles since, and each half's late cycles since (an
 * overrun or a deadline miss; one cycle that did both counts once, {@link LateCycles}, D73),
 * and how many of those were the machine's ({@link MachineStalls}). Reads both halves' control
 * blocks; a half that is gone reads as null. Actor thread.
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
    private final MachineStalls stalls;
    private long lastNewLate;
    private long lastOldLate;

    /**
     * Both halves' late cycles since the baseline, and how many of each were in a stall of the
     * machine (D73): the rest are the half's own.
     */
    record Late(long newLate, long oldLate, long newMachine, long oldMachine, long oldBehindNew, MachineStalls stalls) {
        long newOwn() {
            return newLate - newMachine;
        }

        /** The old half's late cycles set against the new one's: neither the machine's nor maybe the new one's doing. */
        long oldOwn() {
            return oldLate - oldMachine - oldBehindNew;
        }

        /** Whether the new half's own late cycles exceed the old one's plus {@link ChangeSetExecutor#OVERRUN_ALLOWANCE}. */
        boolean beyondAllowance() {
            return CycleCounts.beyondAllowance(newOwn(), oldOwn());
        }

        /**
         * What was not counted, e.g. {@code "; not counted: 3 late cycles of the new one and 4
         * of the old one in the same looks as a late cycle of sim-robot (priority 80) on CPU 0,
         * the machine's"}; empty when nothing was left out.
         */
        String notCounted() {
            String behind = oldBehindNew == 0 ? "" : "; not set against the new one's: " + oldBehindNew + " late cycles "
                    + "of the old one in the same looks (" + ChangeSetExecutor.WATCH_MS + " ms) as the new one's, which "
                    + "may have delayed it on its CPU";
            if (newMachine == 0 && oldMachine == 0) {
                return behind;
            }
            return "; not counted: " + newMachine + " late cycles of the new one and " + oldMachine + " of the old "
                    + "one in the same looks (" + ChangeSetExecutor.WATCH_MS + " ms) as a late cycle of "
                    + stalls.witnesses() + " on CPU " + stalls.cpu() + ", the machine's" + behind;
        }
    }

    CycleCounts(Cell cell, Instance next, RtHalf nextHalf, Instance old, RtHalf oldHalf, boolean neverBack) {
        this.stalls = new MachineStalls(cell, next, old);
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
        lastNewLate = 0;
        lastOldLate = 0;
        stalls.baseline();
    }

    /**
     * One look (D73): both halves' late cycles since the baseline from {@code n} and {@code o}
     * (read before this call, so a stall that made them late shows in the other halves'
     * counters already), those in a stall of the machine counted apart.
     */
    Late look(ControlBlock.Stats n, ControlBlock.Stats o) {
        long newLate = n == null ? lastNewLate : newBad(n);
        long oldLate = o == null ? lastOldLate : oldBad(o);
        stalls.look(Math.max(0, newLate - lastNewLate), Math.max(0, oldLate - lastOldLate));
        lastNewLate = newLate;
        lastOldLate = oldLate;
        return new Late(newLate, oldLate, stalls.newMachine(), stalls.oldMachine(), stalls.oldBehindNew(), stalls);
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
