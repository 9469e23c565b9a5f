package org.arflex.drcr.impl.runtime;

import java.util.function.Consumer;
import org.arflex.drcr.impl.abi.ControlBlock;
import org.arflex.drcr.impl.supervisor.RtHalf;
import org.arflex.planner.Change;

/**
 * Measured WCET, sustained only (actor thread): the execution time of each running RT half
 * against its declared WCET, sampled periodically. Only a sustained exceedance is recorded as
 * the measured WCET and re-planned with ({@link #sustainedOverWcet}); an isolated one (a
 * preemption or a stall of the machine, which a wall-clock execution time includes) is logged
 * once and kept out of admission, so one spike cannot stop a component for good.
 */
final class WcetMonitor {

    /** Cycles of a sampling window above the declared WCET that make an exceedance sustained. */
    static final double SUSTAINED_FRACTION = 0.01;
    static final long SUSTAINED_MIN_CYCLES = 3;

    private final Cell cell;
    private final Consumer<String> log;

    WcetMonitor(Cell cell, Consumer<String> log) {
        this.cell = cell;
        this.log = log;
    }

    /** @return total cycles whose execution time exceeded the declared WCET */
    long sample() {
        cell.actor().checkThread();
        long over = 0;
        for (Instance inst : cell.instances()) {
            RtHalf h = inst.half;
            if (h == null) {
                continue;
            }
            long wcet = inst.contract.timing().wcetNs();
            ControlBlock.Stats s = h.stats(wcet);
            if (s == null) {
                continue;
            }
            over += s.execOverWcet();
            if (s.execCount() < inst.sampledExecCount) {  // a new RT half counts from zero
                inst.sampledExecCount = inst.sampledExecSum = inst.sampledExecOver = 0;
            }
            long dCount = s.execCount() - inst.sampledExecCount;
            long dSum = s.execSumNs() - inst.sampledExecSum;
            long dOver = s.execOverWcet() - inst.sampledExecOver;
            inst.sampledExecCount = s.execCount();
            inst.sampledExecSum = s.execSumNs();
            inst.sampledExecOver = s.execOverWcet();
            if (dCount <= 0 || s.execMaxNs() <= wcet) {
                continue;
            }
            if (sustainedOverWcet(wcet, dCount, dSum, dOver)) {
                measured(inst, s.execMaxNs());
            } else if (dOver > 0 && !inst.transientWcetLogged) {
                inst.transientWcetLogged = true;
                log.accept("arflex: " + inst.name + ": execution time up to " + s.execMaxNs() + " ns above declared WCET "
                        + wcet + " ns in isolated cycles (" + dOver + " of " + dCount + "); not re-planned (logged once)");
            }
        }
        return over;
    }

    /** Records a measured execution time above the declared WCET and re-plans with it. */
    private void measured(Instance inst, long ns) {
        if (ns <= inst.contract.timing().wcetNs() || ns <= inst.measuredWcetNs) {
            return;
        }
        inst.measuredWcetNs = ns;
        log.accept("arflex: " + inst.name + ": measured execution time " + ns + " ns above declared WCET "
                + inst.contract.timing().wcetNs() + " ns; re-planning");
        cell.apply(Change.measuredWcet(inst.name, ns));
    }

    /**
     * Whether one sampling window shows a sustained WCET exceedance: at least 1 % of its cycles
     * (and at least 3) above the declared WCET, or a mean execution time above it. Above the
     * execution-time histogram's range (200 us) the histogram only counts cycles of 200 us or
     * more, an upper bound, so there only the mean decides.
     */
    static boolean sustainedOverWcet(long wcetNs, long cycles, long sumNs, long over) {
        if (cycles <= 0) {
            return false;
        }
        if (sumNs / cycles > wcetNs) {
            return true;
        }
        long histRangeNs = (long) ControlBlock.HIST_BINS * ControlBlock.HIST_BIN_NS;
        return wcetNs < histRangeNs
                && over >= Math.max(SUSTAINED_MIN_CYCLES, (long) Math.ceil(cycles * SUSTAINED_FRACTION));
    }
}
