package org.arflex.drcr.impl.runtime;

import java.util.Locale;
import java.util.concurrent.CompletableFuture;
import java.util.function.Consumer;
import org.arflex.drcr.impl.supervisor.RtHalf;

/**
 * What an update's rollback window says (D38, D53, D55): its progress, and its verdict to the
 * log, the cell's problems, the change set's progress and the set's outcome. The texts are the
 * command's and the console's; tests assert on them. Actor thread.
 */
final class WindowReport {
    private final Cell cell;
    private final Consumer<String> log;
    private final ChangeSetProgress.Apply progress;
    private final ChangeSet set;
    private final String name;
    private final CompletableFuture<String> verdict;

    WindowReport(Cell cell, Consumer<String> log, ChangeSetProgress.Apply progress, ChangeSet set, String name,
                 CompletableFuture<String> verdict) {
        this.cell = cell;
        this.log = log;
        this.progress = progress;
        this.set = set;
        this.name = name;
        this.verdict = verdict;
    }

    /** The new half was refused at its START in the switch turn and the old one runs on (D55). */
    void handedBack(String reason, Instance old, RtHalf oldHalf) {
        String v = "update " + name + ": rolled back at the switch: " + reason + "; pid " + oldHalf.pid() + " ("
                + old.objectId + ") runs it again";
        old.life.reason(null);
        cell.problem("change set " + set.describe() + ": " + v);
        log.accept("arflex: " + v);
        cell.changed();
        progress.verdict(name, ChangeSetProgress.ROLLED_BACK, v, 0);
        verdict.complete(v);
    }

    /**
     * The window is over without a rollback, for {@code why}, after {@code cycles} of the new
     * version; {@code shown}: it was shown in the progress.
     */
    void ended(String why, boolean shown, long cycles) {
        String v = "update " + name + ": " + why;
        log.accept("arflex: " + v);
        cell.changed();
        if (shown) {
            progress.phase(ChangeSetProgress.WINDOW, v);
        }
        progress.verdict(name, ChangeSetProgress.COMMITTED, v, cycles);
        verdict.complete(v);
    }

    /** The component was handed back to {@code old} after {@code cycles} of the new version. */
    void rolledBack(long cycles, String from, String why, Instance old, RtHalf oldHalf, long boundBackNanos) {
        String v = String.format(Locale.ROOT, "update %s: rolled back after %d cycles of the new version "
                + "(%s): %s; pid %d (%s) runs it again (its consumers bound back %.1f ms after the cause was seen)",
                name, cycles, from, why, oldHalf.pid(), old.objectId, boundBackNanos / 1e6);
        old.life.reason(null);
        cell.problem("change set " + set.describe() + ": " + v);
        progress.phase(ChangeSetProgress.WINDOW, v);
        progress.verdict(name, ChangeSetProgress.ROLLED_BACK, v, cycles);
        verdict.complete(v);
    }

    /** The window began: {@code pid} switched to, {@code oldPid} kept warm. */
    void switched(long pid, long window, long oldPid) {
        progress.cycles(ChangeSetProgress.WINDOW, "update " + name + ": switched to pid " + pid + ", rollback window of "
                + window + " cycles, pid " + oldPid + " kept warm", name, 0, window, null, 0, 0);
    }

    /** The window is at {@code cycles} of {@code window}. */
    void cycle(long cycles, long window, long pid, long newBad, long oldBad) {
        progress.cycles(ChangeSetProgress.WINDOW, String.format(Locale.ROOT, "update %s: rollback "
                + "window, cycle %d of %d of pid %d (%d cycles late, the old version %d)", name,
                cycles, window, pid, newBad, oldBad), name, cycles, window, null, 0, 0);
    }

    static String oldExited(long oldPid, String description) {
        return "the old version (pid " + oldPid + ") exited while kept warm (" + description
                + "): no rollback possible any more";
    }

    /** The new half's own late cycles were too many (D38, D73): what was counted, and what not. */
    static String overran(CycleCounts.Late late, long cycles) {
        return String.format(Locale.ROOT, "the new version overran or missed its deadline in %d "
                + "of its first %d cycles (the old one, on the same inputs: %d%s)", late.newOwn(), cycles,
                late.oldOwn(), late.notCounted());
    }

    static String committed(long cycles, CycleCounts.Late late) {
        return String.format(Locale.ROOT, "committed: the new version ran %d cycles (%d cycles late, "
                + "the old one %d%s)", cycles, late.newOwn(), late.oldOwn(), late.notCounted());
    }
}
