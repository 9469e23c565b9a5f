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
 *
 * <p>The value recorded is taken only from executions no single stall inflated (D82; D73's last
 * finding: one stall made a half's measured WCET 4x its declared one and a change set's window
 * inadmissible): each window's sustained level ({@link ExecWindow#levelNs}, the time as many
 * executions reached as make an exceedance sustained), and only when two windows in a row were
 * sustained, the lower of their two levels. The half's lifetime maximum is never used.
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
            ControlBlock.Detail d = h.detail(wcet);
            if (d == null || d.stats() == null) {
                continue;
            }
            ControlBlock.Stats s = d.stats();
            over += s.execOverWcet();
            ControlBlock.Metric now = d.exec() != null ? d.exec()
                    : new ControlBlock.Metric(s.execCount(), 0, s.execMaxNs(), s.execSumNs(), null);
            if (inst.sampledExec != null && now.count() < inst.sampledExec.count()) {  // a new RT half counts from zero
                inst.sampledExec = null;
                inst.sampledExecOver = 0;
                inst.sustainedLevelNs = 0;
            }
            ExecWindow w = ExecWindow.between(inst.sampledExec, now);
            long dOver = s.execOverWcet() - inst.sampledExecOver;
            long levelBefore = inst.sustainedLevelNs;
            inst.sampledExec = now;
            inst.sampledExecOver = s.execOverWcet();
            inst.sustainedLevelNs = 0;
            if (w.cycles() <= 0 || s.execMaxNs() <= wcet) {
                continue;
            }
            long level = sustainedOverWcet(wcet, w.cycles(), w.sumNs(), dOver) ? w.levelNs(sustainedCycles(w.cycles())) : 0;
            if (level > wcet) {
                inst.sustainedLevelNs = level;
                if (levelBefore > wcet) {
                    measured(inst, Math.min(levelBefore, level));
                }
            } else if (dOver > 0 && !inst.transientWcetLogged) {
                inst.transientWcetLogged = true;
                log.accept("arflex: " + inst.name + ": execution time up to " + s.execMaxNs() + " ns above declared WCET "
                        + wcet + " ns in isolated cycles (" + dOver + " of " + w.cycles() + "); not re-planned (logged once)");
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
                + inst.contract.timing().wcetNs() + " ns (sustained in two sampling windows in a row); re-planning");
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
        return wcetNs < histRangeNs && over >= sustainedCycles(cycles);
    }

    /** How many cycles of a window of {@code cycles} make an exceedance sustained: 1 %, at least 3. */
    static long sustainedCycles(long cycles) {
        return Math.max(SUSTAINED_MIN_CYCLES, (long) Math.ceil(cycles * SUSTAINED_FRACTION));
    }
}
