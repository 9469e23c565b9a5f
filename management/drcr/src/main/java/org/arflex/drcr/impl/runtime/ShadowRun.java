package org.arflex.drcr.impl.runtime;

import java.util.List;
import java.util.function.Consumer;
import org.arflex.drcr.impl.lifecycle.Actor;
import org.arflex.drcr.impl.supervisor.RtHalf;
import org.arflex.planner.Wire;

/**
 * The shadow run of an update in a change set (docs/DECISIONS.md D42), before its switch: the
 * new version's READY half is bound to the providers its plan gives it and started, no consumer
 * bound to it ({@link ShadowStart}). For {@code shadow} cycles of the new half it looks every
 * {@link ChangeSetExecutor#WATCH_MS} at both halves ({@link ShadowChecks}) and rejects the update
 * when the new one exits (reported by the change set through {@link #exited}) or a look finds a
 * rule broken; the texts are {@link ShadowReport}'s. Passing, the change set switches as without
 * a shadow run, adopting the running half ({@link Starter#adopt}: no second BIND or START).
 * Rejected, the change set is torn down: the new half stops, nothing else was touched. Actor
 * thread.
 */
final class ShadowRun {

    /** What the change set does with the outcome (actor thread). */
    interface Outcome {
        void passed(ShadowRun s, String summary);

        void rejected(ShadowRun s, String why);
    }

    final ChangeSet.Update update;
    final Instance old;
    final RtHalf oldHalf;
    final Instance next;
    final RtHalf nextHalf;
    private final Cell cell;
    private final Segments segments;
    private final Consumer<String> log;
    private final Outcome outcome;
    /** Where the change set says how far it is (D53). */
    private final ChangeSetProgress.Apply progress;
    private final ShadowChecks checks;
    private Actor.Cancellable timer;
    private boolean done;

    ShadowRun(Cell cell, Segments segments, Consumer<String> log, ChangeSetProgress.Apply progress, Outcome outcome,
              ChangeSet.Update update, Instance old, RtHalf oldHalf, Instance next, RtHalf nextHalf) {
        this.progress = progress;
        this.cell = cell;
        this.segments = segments;
        this.log = log;
        this.outcome = outcome;
        this.update = update;
        this.old = old;
        this.oldHalf = oldHalf;
        this.next = next;
        this.nextHalf = nextHalf;
        this.checks = new ShadowChecks(cell, update, old, oldHalf, next, nextHalf);
    }

    /** Binds the new half to its providers and starts it; no consumer is touched. */
    void begin(List<Wire> wiring) {
        String refused = ShadowStart.begin(cell, segments, next, nextHalf, wiring,
                cell.config().monotonicNs().getAsLong());
        if (refused != null) {
            reject(refused);
            return;
        }
        long nowMs = cell.actor().clock().millis();
        log.accept("arflex: " + next.name + ": the new version (pid " + nextHalf.pid() + ", " + next.objectId
                + ") runs in shadow for " + update.shadow() + " cycles on inputs " + next.bound
                + ", its outputs read by nobody; compared with pid " + oldHalf.pid() + " by "
                + (update.tolerances().isEmpty() ? "no tolerance" : update.tolerances()));
        checks.started(nowMs);
        timer = cell.actor().schedule(this::look, ChangeSetExecutor.WATCH_MS);
        publish(0, 0);
    }

    private void publish(long cycles, long bad) {
        ShadowReport.publish(progress, update, next.name, nextHalf.pid(), checks.comparison, cycles, bad);
    }

    /** The new half's cycles since its START; the last seen once it is gone. */
    long cycles() {
        return checks.counts.cycles();
    }

    /**
     * The new half exited before the switch (the change set's exit hook, actor thread).
     *
     * @return true when that rejected the update here (the run was still going)
     */
    boolean exited(RtHalf.Exit ex) {
        if (done) {
            return false;
        }
        cycles();
        reject("the new version (pid " + nextHalf.pid() + ") exited: " + ex.description());
        return true;
    }

    /** Ends the run without an outcome (the set is torn down for another reason). */
    void cancel() {
        done = true;
        if (timer != null) {
            timer.cancel();
            timer = null;
        }
        cell.monitor().unwatch(nextHalf);
    }

    private void look() {
        timer = null;
        if (done) {
            return;
        }
        ShadowChecks.Look l = checks.look(cell.actor().clock().millis());
        if (l == null) { // gone or unreadable: its exit comes to exited()
            timer = cell.actor().schedule(this::look, ChangeSetExecutor.WATCH_MS);
        } else if (l.rejected() != null) {
            reject(l.rejected());
        } else if (l.cycles() >= update.shadow()) {
            done = true;
            cell.monitor().unwatch(nextHalf); // watched again as the component's half at the switch
            publish(l.cycles(), l.newBad());
            outcome.passed(this, ShadowReport.passed(update.tolerances(), checks.comparison, l.cycles(), l.newBad(),
                    l.oldBad()));
        } else {
            if (l.moved()) {
                publish(l.cycles(), l.newBad());
            }
            timer = cell.actor().schedule(this::look, ChangeSetExecutor.WATCH_MS);
        }
    }

    private void reject(String why) {
        done = true;
        if (timer != null) {
            timer.cancel();
            timer = null;
        }
        cell.monitor().unwatch(nextHalf);
        outcome.rejected(this, why);
    }
}
