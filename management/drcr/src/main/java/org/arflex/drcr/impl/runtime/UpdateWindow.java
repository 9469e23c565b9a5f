package org.arflex.drcr.impl.runtime;

import java.util.List;
import java.util.Map;
import java.util.function.Consumer;
import org.arflex.drcr.impl.lifecycle.State;
import org.arflex.drcr.impl.supervisor.RtHalf;
import org.arflex.planner.Change;
import org.arflex.planner.Plan;

/**
 * An update after its switch (D38): the old half keeps running on its inputs, unread, for
 * {@code window} cycles of the new one; a crash of the new half, or more overruns and
 * deadline misses than the old had in the same cycles (plus {@link ChangeSetExecutor#OVERRUN_ALLOWANCE}),
 * rolls the component back: the old half is the component's again and its consumers are
 * bound back to its segments (each at its next cycle boundary), the new half stops. Else the
 * old half stops when the window is over. Actor thread.
 */
final class UpdateWindow {
    final ChangeSet set;
    final ChangeSet.Update update;
    final Instance old;
    final RtHalf oldHalf;
    final Instance next;
    final RtHalf nextHalf;
    final java.util.concurrent.CompletableFuture<String> verdict = new java.util.concurrent.CompletableFuture<>();
    long cycles0;
    long lastCycles;
    long newBad0;
    long oldBad0;
    long tEndNs;
    org.arflex.drcr.impl.lifecycle.Actor.Cancellable timer;
    boolean done;
    /** The window's cycles last published (D53). */
    private long lastPublished = -1;

    private final ChangeSetExecutor owner;
    private final Cell cell;
    private final Stops stops;
    private final Segments segments;
    private final Consumer<String> log;
    /** Where the change set says how far it is (D53). */
    private final ChangeSetProgress.Apply progress;
    /** The executor's open windows, by component name (actor thread). */
    private final Map<String, UpdateWindow> warm;

    UpdateWindow(ChangeSetExecutor owner, Cell cell, Stops stops, Segments segments, Consumer<String> log,
                 ChangeSetProgress.Apply progress, Map<String, UpdateWindow> warm, ChangeSet set, ChangeSet.Update update, Instance old, RtHalf oldHalf,
                 Instance next) {
        this.owner = owner;
        this.cell = cell;
        this.stops = stops;
        this.segments = segments;
        this.log = log;
        this.progress = progress;
        this.warm = warm;
        this.set = set;
        this.update = update;
        this.old = old;
        this.oldHalf = oldHalf;
        this.next = next;
        this.nextHalf = next.half;
    }

    void begin() {
        if (nextHalf == null) {
            done = true;
            if (cell.find(next.name) == old && old.half == oldHalf) { // handed back in the switch turn (D55)
                String v = "update " + next.name + ": rolled back at the switch: " + next.destroyReason + "; pid "
                        + oldHalf.pid() + " (" + old.objectId + ") runs it again";
                old.life.reason(null);
                cell.problem("change set " + set.describe() + ": " + v);
                log.accept("arflex: " + v);
                cell.changed();
                verdict.complete(v);
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
                end("the old version (pid " + oldHalf.pid() + ") exited while kept warm (" + ex.description()
                        + "): no rollback possible any more", cyclesNow());
            }
        }));
        log.accept("arflex: " + next.name + ": update switched to pid " + nextHalf.pid() + " (" + next.objectId
                + "); the old version (pid " + oldHalf.pid() + ", " + old.objectId + ") is kept warm for "
                + update.window() + " cycles");
        progress.cycles(ChangeSetProgress.WINDOW, "update " + next.name + ": switched to pid " + nextHalf.pid()
                + ", rollback window of " + update.window() + " cycles, pid " + oldHalf.pid() + " kept warm", next.name,
                0, update.window(), null, 0, 0);
        // the counters' baseline right after the switch turn, which it would only lengthen
        cell.actor().submit(this::baseline);
    }

    private void baseline() {
        if (done) {
            return;
        }
        org.arflex.drcr.impl.abi.ControlBlock.Stats n = ChangeSetExecutor.stats(nextHalf, next);
        org.arflex.drcr.impl.abi.ControlBlock.Stats o = ChangeSetExecutor.stats(oldHalf, old);
        cycles0 = n == null ? 0 : n.cycles();
        newBad0 = ChangeSetExecutor.bad(n);
        oldBad0 = ChangeSetExecutor.bad(o);
        timer = cell.actor().schedule(this::watch, ChangeSetExecutor.WATCH_MS);
    }

    /** The new half's cycles since the switch; the last seen once it is gone. */
    long cyclesNow() {
        org.arflex.drcr.impl.abi.ControlBlock.Stats n = ChangeSetExecutor.stats(nextHalf, next);
        if (n != null) {
            lastCycles = n.cycles() - cycles0;
        }
        return lastCycles;
    }

    private void watch() {
        timer = null;
        if (done) {
            return;
        }
        org.arflex.drcr.impl.abi.ControlBlock.Stats n = ChangeSetExecutor.stats(nextHalf, next);
        org.arflex.drcr.impl.abi.ControlBlock.Stats o = ChangeSetExecutor.stats(oldHalf, old);
        long cycles = cyclesNow();
        long newBad = ChangeSetExecutor.bad(n) - newBad0;
        long oldBad = ChangeSetExecutor.bad(o) - oldBad0;
        String outside = outside(cell, next, update.envelopes());
        if (outside != null) {
            rollback(outside, System.nanoTime());
            return;
        }
        if (newBad > oldBad + ChangeSetExecutor.OVERRUN_ALLOWANCE) {
            rollback(String.format(java.util.Locale.ROOT, "the new version overran or missed its deadline in %d "
                    + "of its first %d cycles (the old one, on the same inputs: %d)", newBad, cycles, oldBad),
                    System.nanoTime());
            return;
        }
        if (cycles >= update.window() || cell.config().monotonicNs().getAsLong() - tEndNs >= 0) {
            end(String.format(java.util.Locale.ROOT, "committed: the new version ran %d cycles (%d overruns or "
                    + "deadline misses, the old one %d)", cycles, newBad, oldBad), cycles);
            return;
        }
        if (cycles != lastPublished) {
            lastPublished = cycles;
            progress.cycles(ChangeSetProgress.WINDOW, String.format(java.util.Locale.ROOT, "update %s: rollback "
                    + "window, cycle %d of %d of pid %d (%d overruns or deadline misses, the old version %d)", next.name,
                    cycles, update.window(), nextHalf.pid(), newBad, oldBad), next.name, cycles, update.window(), null, 0, 0);
        }
        timer = cell.actor().schedule(this::watch, ChangeSetExecutor.WATCH_MS);
    }

    /** Which newest value of {@code next}'s outputs lies outside its envelope, or null (also in a shadow run, D42). */
    static String outside(Cell cell, Instance next, List<ChangeSet.Envelope> envelopes) {
        for (ChangeSet.Envelope e : envelopes) {
            org.arflex.drcr.impl.supervisor.RtLauncher.Output o = next.outputs.get(e.port());
            org.arflex.contract.PortSpec spec = next.contract.outputs().stream()
                    .filter(p -> p.name().equals(e.port())).findFirst().orElse(null);
            org.arflex.contract.PortType t = spec == null ? null : cell.config().types().find(spec.type()).orElse(null);
            if (o == null || t == null) {
                continue;
            }
            byte[] v;
            try {
                v = o.newest(t.name(), (int) t.size());
            } catch (java.io.IOException | RuntimeException ex) {
                continue; // not readable now: the next look
            }
            if (v == null) {
                continue;
            }
            for (org.arflex.drcr.dto.PortFieldDTO f : PortValues.decode(t,
                    java.nio.ByteBuffer.wrap(v).order(java.nio.ByteOrder.LITTLE_ENDIAN))) {
                if (!f.name.equals(e.field())) {
                    continue;
                }
                for (int i = 0; i < f.values.length; i++) {
                    double x = f.values[i];
                    if (!(x >= e.min() && x <= e.max())) {
                        return String.format(java.util.Locale.ROOT, "output %s.%s%s = %s left the envelope [%s, %s] "
                                + "declared for the update", e.port(), e.field(), f.count > 1 ? "[" + i + "]" : "",
                                x, e.min(), e.max());
                    }
                }
            }
        }
        return null;
    }

    /** The window is over without a rollback: the old half stops, its segments go after it. */
    void end(String why, long cycles) {
        done = true;
        warm.remove(next.name, this);
        if (timer != null) {
            timer.cancel();
            timer = null;
        }
        old.life.target(State.DESTROYED);
        old.destroyReason = "replaced by its new version (" + set.describe() + ")";
        if (!oldHalf.exit().isDone()) {
            long settle = Math.max(100, 3 * old.contract.timing().periodNs() / 1_000_000L);
            stops.submit(List.of(new Stops.Going(old, oldHalf, List.copyOf(old.bound.keySet()), settle,
                    old.destroyReason)));
        } else {
            segments.close(old);
            old.life.to(State.DESTROYED, old.destroyReason);
        }
        old.bound.clear();
        String v = "update " + next.name + ": " + why;
        log.accept("arflex: " + v);
        cell.changed();
        if (update.window() > 0 && nextHalf != null) {
            progress.phase(ChangeSetProgress.WINDOW, v);
        }
        verdict.complete(v);
    }

    /**
     * The old half is the component's again; the new one stops (actor thread).
     *
     * @param seenNanos when the cause was seen ({@link System#nanoTime()}): an exit's waiter thread, or now
     */
    void rollback(String why, long seenNanos) {
        done = true;
        warm.remove(next.name, this);
        if (timer != null) {
            timer.cancel();
            timer = null;
        }
        long cycles = cyclesNow();
        long boundBackNanos = 0;
        next.half = null;
        cell.monitor().unwatch(nextHalf);
        cell.swap(next, old);
        old.half = oldHalf;
        // the consumers first (they read a dead or failing half until their BIND is taken),
        // then the planner, then once more should the old contract's wiring differ
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
            long settle = Math.max(100, 3 * next.contract.timing().periodNs() / 1_000_000L);
            stops.submit(List.of(new Stops.Going(next, nextHalf, List.copyOf(next.bound.keySet()), settle,
                    next.destroyReason)));
            next.bound.clear();
        }
        String v = String.format(java.util.Locale.ROOT, "update %s: rolled back after %d cycles of the new version "
                + "(%s): %s; pid %d (%s) runs it again (its consumers bound back %.1f ms after the cause was seen)",
                next.name, cycles, update.from(), why, oldHalf.pid(), old.objectId, boundBackNanos / 1e6);
        old.life.reason(null);
        cell.problem("change set " + set.describe() + ": " + v);
        progress.phase(ChangeSetProgress.WINDOW, v);
        verdict.complete(v);
    }
}
