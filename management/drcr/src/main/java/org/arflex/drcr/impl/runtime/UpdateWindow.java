package org.arflex.drcr.impl.runtime;

import java.util.List;
import java.util.Map;
import java.util.concurrent.CompletableFuture;
import java.util.function.Consumer;
import org.arflex.drcr.impl.abi.ControlBlock;
import org.arflex.drcr.impl.lifecycle.Actor;
import org.arflex.drcr.impl.supervisor.RtHalf;

/**
 * An update after its switch (D38): the old half keeps running on its inputs, unread, for
 * {@code window} cycles of the new one; a crash of the new half, an output outside an envelope
 * ({@link Envelopes}), or more late cycles than the old had in the same cycles, the machine's
 * stalls apart (plus {@link ChangeSetExecutor#OVERRUN_ALLOWANCE}, {@link CycleCounts}, D73) rolls the component
 * back: the old half is the component's again and its consumers are bound back to its segments
 * (each at its next cycle boundary), the new half stops. Else the old half stops when the window
 * is over ({@link WindowHandOver} does either; the texts are {@link WindowReport}'s). Actor thread.
 */
final class UpdateWindow {
    final ChangeSet set;
    final ChangeSet.Update update;
    final Instance old;
    final RtHalf oldHalf;
    final Instance next;
    final RtHalf nextHalf;
    final CompletableFuture<String> verdict = new CompletableFuture<>();
    private final CycleCounts counts;
    private long tEndNs;
    private Actor.Cancellable timer;
    private boolean done;
    /** The window's cycles last published (D53). */
    private long lastPublished = -1;

    private final Cell cell;
    private final WindowHandOver handOver;
    private final Consumer<String> log;
    private final WindowReport report;
    /** The executor's open windows, by component name (actor thread). */
    private final Map<String, UpdateWindow> warm;

    UpdateWindow(ChangeSetExecutor owner, Cell cell, Stops stops, Segments segments, Consumer<String> log,
                 ChangeSetProgress.Apply progress, Map<String, UpdateWindow> warm, ChangeSet set, ChangeSet.Update update,
                 Instance old, RtHalf oldHalf, Instance next) {
        this.cell = cell;
        this.handOver = new WindowHandOver(owner, cell, stops, segments, log);
        this.log = log;
        // the verdict (and with it the command that applied the set) once the half that goes is
        // gone and recorded: a set applied next finds the component with one half, not refused
        // for a stop still pending (a CI run: "'vision' has no running RT half to update")
        CompletableFuture<String> decided = new CompletableFuture<>();
        this.report = new WindowReport(cell, log, progress, set, next.name, decided);
        decided.whenComplete((v, e) -> stops.recorded(List.of(old, next)).whenComplete((x, y) -> {
            if (e != null) {
                verdict.completeExceptionally(e);
            } else {
                verdict.complete(v);
            }
        }));
        this.warm = warm;
        this.set = set;
        this.update = update;
        this.old = old;
        this.oldHalf = oldHalf;
        this.next = next;
        this.nextHalf = next.half;
        this.counts = nextHalf == null ? null : new CycleCounts(cell, next, nextHalf, old, oldHalf, false);
    }

    void begin() {
        if (nextHalf == null) {
            done = true;
            if (cell.find(next.name) == old && old.half == oldHalf) { // handed back in the switch turn (D55)
                report.handedBack(next.destroyReason, old, oldHalf);
                return;
            }
            end("the new version did not start", 0);
            return;
        }
        if (update.window() == 0) {
            end("committed at the switch (no rollback window)", 0);
            return;
        }
        long period = Math.max(1, next.contract.timing().periodNs());
        // a half that does not cycle (sporadic, starved) ends its window by time
        tEndNs = cell.config().monotonicNs().getAsLong() + 4 * update.window() * period + 1_000_000_000L;
        warm.put(next.name, this);
        oldHalf.exit().thenAccept(ex -> cell.actor().submit(() -> {
            if (!done) {
                oldHalf.cleanup();
                end(WindowReport.oldExited(oldHalf.pid(), ex.description()), cyclesNow());
            }
        }));
        log.accept("arflex: " + next.name + ": update switched to pid " + nextHalf.pid() + " (" + next.objectId
                + "); the old version (pid " + oldHalf.pid() + ", " + old.objectId + ") is kept warm for "
                + update.window() + " cycles");
        report.switched(nextHalf.pid(), update.window(), oldHalf.pid());
        // the counters' baseline right after the switch turn, which it would only lengthen
        cell.actor().submit(this::baseline);
    }

    private void baseline() {
        if (done) {
            return;
        }
        counts.baseline();
        timer = cell.actor().schedule(this::watch, ChangeSetExecutor.WATCH_MS);
    }

    /** The new half's cycles since the switch; the last seen once it is gone. */
    long cyclesNow() {
        return counts == null ? 0 : counts.cycles();
    }

    private void watch() {
        timer = null;
        if (done) {
            return;
        }
        ControlBlock.Stats n = counts.newStats();
        ControlBlock.Stats o = counts.oldStats();
        long cycles = cyclesNow();
        CycleCounts.Late late = counts.look(n, o);
        long newBad = late.newLate();
        long oldBad = late.oldLate();
        String outside = Envelopes.outside(cell, next, update.envelopes());
        if (outside != null) {
            rollback(outside, System.nanoTime());
        } else if (late.beyondAllowance()) {
            rollback(WindowReport.overran(late, cycles), System.nanoTime());
        } else if (cycles >= update.window() || cell.config().monotonicNs().getAsLong() - tEndNs >= 0) {
            end(WindowReport.committed(cycles, late), cycles);
        } else {
            if (cycles != lastPublished) {
                lastPublished = cycles;
                report.cycle(cycles, update.window(), nextHalf.pid(), newBad, oldBad);
            }
            timer = cell.actor().schedule(this::watch, ChangeSetExecutor.WATCH_MS);
        }
    }

    /** The window is over without a rollback: the old half stops, its segments go after it. */
    void end(String why, long cycles) {
        close();
        handOver.retire(set, old, oldHalf);
        report.ended(why, update.window() > 0 && nextHalf != null, cycles);
    }

    /**
     * The old half is the component's again; the new one stops (actor thread).
     *
     * @param seenNanos when the cause was seen ({@link System#nanoTime()}): an exit's waiter thread, or now
     */
    void rollback(String why, long seenNanos) {
        close();
        long cycles = cyclesNow();
        long boundBackNanos = handOver.handBack(next, nextHalf, old, oldHalf, why, seenNanos);
        report.rolledBack(cycles, update.from(), why, old, oldHalf, boundBackNanos);
    }

    private void close() {
        done = true;
        warm.remove(next.name, this);
        if (timer != null) {
            timer.cancel();
            timer = null;
        }
    }
}
