package org.arflex.drcr.impl.runtime;

import java.util.List;
import java.util.function.Consumer;
import org.arflex.drcr.impl.lifecycle.State;
import org.arflex.drcr.impl.supervisor.RtHalf;
import org.arflex.planner.Change;
import org.arflex.planner.Plan;

/**
 * The two ends of an update's rollback window (D38): the old half retired once the window is
 * over, or the component handed back to it (its consumers bound back, the planner given the old
 * contract, the new half stopped). Actor thread.
 */
final class WindowHandOver {
    private final ChangeSetExecutor owner;
    private final Cell cell;
    private final Stops stops;
    private final Segments segments;
    private final Consumer<String> log;

    WindowHandOver(ChangeSetExecutor owner, Cell cell, Stops stops, Segments segments, Consumer<String> log) {
        this.owner = owner;
        this.cell = cell;
        this.stops = stops;
        this.segments = segments;
        this.log = log;
    }

    /** The window is over without a rollback: the old half stops, its segments go after it. */
    void retire(ChangeSet set, Instance old, RtHalf oldHalf) {
        old.life.target(State.DESTROYED);
        old.destroyReason = "replaced by its new version (" + set.describe() + ")";
        if (!oldHalf.exit().isDone()) {
            stop(old, oldHalf);
        } else {
            segments.close(old);
            old.life.to(State.DESTROYED, old.destroyReason);
        }
        old.bound.clear();
    }

    /**
     * The old half is the component's again, its consumers bound back first (they read a dead or
     * failing half until their BIND is taken), then the planner, then once more should the old
     * contract's wiring differ; the new one stops.
     *
     * @param seenNanos when the cause was seen ({@link System#nanoTime()})
     * @return how long after {@code seenNanos} the consumers were bound back, in ns
     */
    long handBack(Instance next, RtHalf nextHalf, Instance old, RtHalf oldHalf, String why, long seenNanos) {
        long boundBackNanos = 0;
        next.half = null;
        cell.monitor().unwatch(nextHalf);
        cell.swap(next, old);
        old.half = oldHalf;
        for (int pass = 0; pass < 2; pass++) {
            Plan now = cell.planner().current();
            for (Instance inst : cell.instances()) {
                if (inst.half != null && inst != old) {
                    owner.rebind(inst, now, "the rollback of " + next.name);
                }
            }
            if (pass == 0) {
                boundBackNanos = System.nanoTime() - seenNanos;
                try {
                    cell.planner().apply(Change.replace(old.contract));
                } catch (RuntimeException e) {
                    log.accept("arflex: " + next.name + ": the planner refused the old contract back: " + e.getMessage());
                }
            }
        }
        next.life.target(State.DESTROYED);
        next.destroyReason = "rolled back: " + why;
        if (nextHalf.exit().isDone()) {
            nextHalf.cleanup();
            next.bound.clear();
            segments.close(next);
            next.life.to(State.DESTROYED, next.destroyReason);
        } else {
            stop(next, nextHalf);
            next.bound.clear();
        }
        return boundBackNanos;
    }

    /** Stops {@code half} of {@code inst} on the stop thread, its inputs unbound, for its destroy reason. */
    private void stop(Instance inst, RtHalf half) {
        long settle = Math.max(100, 3 * inst.contract.timing().periodNs() / 1_000_000L);
        stops.submit(List.of(new Stops.Going(inst, half, List.copyOf(inst.bound.keySet()), settle,
                inst.destroyReason)));
    }
}
