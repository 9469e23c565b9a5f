package org.arflex.drcr.impl.runtime;

import org.arflex.drcr.impl.abi.ControlBlock;
import org.arflex.drcr.impl.supervisor.RtHalf;

/**
 * The rules one look of a shadow run applies (D42), in their order. The update is rejected when
 * the new half
 * <ul>
 * <li>overruns or misses its deadline in more cycles than the running version in the same time,
 * plus {@link ChangeSetExecutor#OVERRUN_ALLOWANCE}, the machine's stalls apart ({@link CycleCounts}, D73);</li>
 * <li>gives an output value outside an envelope ({@link Envelopes}), or a field whose value
 * differs from the running version's by more than its tolerance ({@link ShadowComparison});</li>
 * <li>stops cycling for its heartbeat timeout, or has not run its cycles within four times their
 * periods plus a second ({@link ShadowTimeLimits});</li>
 * <li>compared no value at all when tolerances are declared (fail closed).</li>
 * </ul>
 * (Its exit is the change set's to report, {@link ShadowRun#exited}.) Actor thread.
 */
final class ShadowChecks {

    /** What one look saw: the new half's cycles since its START, both halves' overruns, why it rejects or null. */
    record Look(long cycles, boolean moved, long newBad, long oldBad, String rejected) {
    }

    final CycleCounts counts;
    final ShadowComparison comparison;
    private final Cell cell;
    private final ChangeSet.Update update;
    private final Instance next;
    private ShadowTimeLimits limits;

    ShadowChecks(Cell cell, ChangeSet.Update update, Instance old, RtHalf oldHalf, Instance next, RtHalf nextHalf) {
        this.cell = cell;
        this.update = update;
        this.next = next;
        this.counts = new CycleCounts(cell, next, nextHalf, old, oldHalf, true);
        this.comparison = new ShadowComparison(cell, update.tolerances(), old, oldHalf, next);
    }

    /** The new half was started at {@code nowMs} (the actor's clock): its time begins, its counters from now. */
    void started(long nowMs) {
        limits = new ShadowTimeLimits(next, update.shadow(), nowMs);
        counts.baseline();
    }

    /** One look at {@code nowMs}; null when the new half's counters cannot be read (gone: its exit follows). */
    Look look(long nowMs) {
        ControlBlock.Stats n = counts.newStats();
        if (n == null) {
            return null;
        }
        long before = counts.lastCycles();
        long cycles = counts.cycles();
        if (cycles != before) {
            limits.progressed(nowMs);
        }
        CycleCounts.Late late = counts.look(n, counts.oldStats());
        return new Look(cycles, cycles != before, late.newLate(), late.oldLate(), why(nowMs, cycles, late));
    }

    private String why(long nowMs, long cycles, CycleCounts.Late late) {
        if (late.beyondAllowance()) {
            return ShadowReport.overran(late, cycles);
        }
        String outside = Envelopes.outside(cell, next, update.envelopes());
        if (outside != null) {
            return outside;
        }
        String differs = comparison.compare();
        if (differs != null) {
            return differs;
        }
        String silent = limits.silent(nowMs, cycles);
        if (silent != null) {
            return silent;
        }
        if (cycles >= update.shadow()) {
            return !update.tolerances().isEmpty() && comparison.compared() == 0
                    ? ShadowReport.noneCompared(cycles, update.tolerances()) : null;
        }
        return limits.overdue(nowMs, cycles);
    }
}
