package org.arflex.drcr.impl.runtime;

import java.io.IOException;
import java.nio.ByteBuffer;
import java.nio.ByteOrder;
import java.util.List;
import java.util.Locale;
import java.util.function.Consumer;
import org.arflex.contract.PortSpec;
import org.arflex.contract.PortType;
import org.arflex.drcr.dto.PortFieldDTO;
import org.arflex.drcr.impl.abi.ControlBlock;
import org.arflex.drcr.impl.lifecycle.Actor;
import org.arflex.drcr.impl.supervisor.RtHalf;
import org.arflex.drcr.impl.supervisor.RtLauncher;
import org.arflex.planner.Wire;

/**
 * The shadow run of an update in a change set (docs/DECISIONS.md D42), before its switch: the
 * new version's READY half is bound to the providers its plan gives it (the running version's
 * own providers) and started, but no consumer is bound to it, so its outputs are computed and
 * read by nobody but this class. For {@code shadow} cycles of the new half it looks every
 * {@link ChangeSetExecutor#WATCH_MS} at both halves and rejects the update when the new one
 * <ul>
 * <li>exits (a crash, or a kill) — reported by the change set through {@link #exited};</li>
 * <li>stops cycling for its heartbeat timeout;</li>
 * <li>overruns or misses its deadline in more cycles than the running version in the same time,
 * plus {@link ChangeSetExecutor#OVERRUN_ALLOWANCE};</li>
 * <li>gives an output value outside an envelope, or a field whose value differs from the running
 * version's by more than its tolerance. Values are compared for the same source cycle: when the
 * port type has a field {@code t_ns} (the time its value is for, which a stage passes on from its
 * input) the newest value of each half is read until both carry the same stamp (four attempts
 * per look; a look that finds none compares nothing); a type without {@code t_ns} compares
 * newest with newest, so its tolerance must cover what one cycle changes;</li>
 * <li>has not run its cycles within four times their periods plus a second (a half that does not
 * cycle), or compared no value at all when tolerances are declared (fail closed).</li>
 * </ul>
 * Passing, the change set switches as without a shadow run, adopting the running half
 * ({@link Starter#adopt}: no second BIND or START). Rejected, the change set is torn down: the
 * new half stops, nothing else was touched. Actor thread.
 */
final class ShadowRun {

    /** What the change set does with the outcome (actor thread). */
    interface Outcome {
        void passed(ShadowRun s, String summary);

        void rejected(ShadowRun s, String why);
    }

    /** Attempts per look to read both halves' values of one source cycle. */
    static final int SAME_STAMP_ATTEMPTS = 4;
    /** The field that carries a value's source time (when its type has one). */
    static final String STAMP = "t_ns";

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
    private Actor.Cancellable timer;
    private boolean done;
    private long cycles0;
    private long lastCycles;
    private long newBad0;
    private long oldBad0;
    /** On the actor's clock ({@link org.arflex.drcr.impl.lifecycle.Clock#millis()}), which its looks follow. */
    private long tEndMs;
    private long limitMs;
    private long lastProgressMs;
    /** Values of the same source cycle compared so far, and the largest difference of each tolerance. */
    private long compared;
    private final double[] largest;

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
        this.largest = new double[update.tolerances().size()];
    }

    /** Binds the new half to its providers and starts it; no consumer is touched. */
    void begin(List<Wire> wiring) {
        long now = cell.config().monotonicNs().getAsLong();
        try {
            next.bound.clear();
            for (Wire w : wiring) {
                String seg = segments.name(w.provider(), w.outPort());
                nextHalf.bind(w.inPort(), seg);
                next.bound.put(w.inPort(), seg);
            }
            nextHalf.runtimeHeartbeat(now);
            nextHalf.start();
        } catch (IOException | RuntimeException e) {
            reject("its BIND or START was refused: " + e.getMessage());
            return;
        }
        // the runtime's heartbeat goes to it as to every started half; a hang is seen below
        // (the monitor's hang report finds no instance running this half and kills nothing)
        cell.monitor().watch(next.name, nextHalf, next.contract.fault().heartbeatTimeoutMs(), now);
        long period = Math.max(1, next.contract.timing().periodNs());
        limitMs = (4 * update.shadow() * period + 1_000_000_000L) / 1_000_000L;
        lastProgressMs = cell.actor().clock().millis();
        tEndMs = lastProgressMs + limitMs;
        log.accept("arflex: " + next.name + ": the new version (pid " + nextHalf.pid() + ", " + next.objectId
                + ") runs in shadow for " + update.shadow() + " cycles on inputs " + next.bound
                + ", its outputs read by nobody; compared with pid " + oldHalf.pid() + " by "
                + (update.tolerances().isEmpty() ? "no tolerance" : update.tolerances()));
        ControlBlock.Stats n = ChangeSetExecutor.stats(nextHalf, next);
        ControlBlock.Stats o = ChangeSetExecutor.stats(oldHalf, old);
        cycles0 = n == null ? 0 : n.cycles();
        newBad0 = ChangeSetExecutor.bad(n);
        oldBad0 = ChangeSetExecutor.bad(o);
        timer = cell.actor().schedule(this::look, ChangeSetExecutor.WATCH_MS);
        publish(0, 0);
    }

    /**
     * Says how far the run is (D53): its cycles, and the compared field closest to its
     * tolerance so far (the largest difference relative to the tolerance).
     */
    private void publish(long cycles, long bad) {
        int worst = -1;
        for (int i = 0; i < largest.length; i++) {
            double abs = update.tolerances().get(i).abs();
            double r = abs > 0 ? largest[i] / abs : largest[i];
            if (worst < 0 || r > (update.tolerances().get(worst).abs() > 0
                    ? largest[worst] / update.tolerances().get(worst).abs() : largest[worst])) {
                worst = i;
            }
        }
        ChangeSet.Tolerance t = worst < 0 ? null : update.tolerances().get(worst);
        progress.cycles(ChangeSetProgress.SHADOW, String.format(Locale.ROOT, "update %s: shadow run of pid %d, cycle %d "
                + "of %d, %d values compared, %d overruns or deadline misses%s", next.name, nextHalf.pid(), cycles,
                update.shadow(), compared, bad, t == null ? "" : String.format(Locale.ROOT,
                        ", worst %s.%s %.3g from the running version's (tolerance %s)", t.port(), t.field(),
                        largest[worst], t.abs())), next.name, cycles, update.shadow(),
                t == null ? null : t.port() + "." + t.field(), t == null ? 0 : largest[worst], t == null ? 0 : t.abs());
    }

    /** The new half's cycles since its START; the last seen once it is gone. */
    long cycles() {
        ControlBlock.Stats n = ChangeSetExecutor.stats(nextHalf, next);
        if (n != null) {
            lastCycles = Math.max(lastCycles, n.cycles() - cycles0);
        }
        return lastCycles;
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
        long now = cell.actor().clock().millis();
        ControlBlock.Stats n = ChangeSetExecutor.stats(nextHalf, next);
        if (n == null) { // gone or unreadable: its exit comes to exited()
            timer = cell.actor().schedule(this::look, ChangeSetExecutor.WATCH_MS);
            return;
        }
        long before = lastCycles;
        long cycles = cycles();
        if (cycles != before) {
            lastProgressMs = now;
        }
        long newBad = ChangeSetExecutor.bad(n) - newBad0;
        long oldBad = ChangeSetExecutor.bad(ChangeSetExecutor.stats(oldHalf, old)) - oldBad0;
        if (newBad > oldBad + ChangeSetExecutor.OVERRUN_ALLOWANCE) {
            reject(String.format(Locale.ROOT, "it overran or missed its deadline in %d of its %d cycles (the running "
                    + "version, on the same inputs: %d; allowed %d more)", newBad, cycles, oldBad,
                    ChangeSetExecutor.OVERRUN_ALLOWANCE));
            return;
        }
        String outside = UpdateWindow.outside(cell, next, update.envelopes());
        if (outside != null) {
            reject(outside);
            return;
        }
        String differs = compare();
        if (differs != null) {
            reject(differs);
            return;
        }
        long silentMs = now - lastProgressMs;
        if (cycles < update.shadow() && silentMs >= next.contract.fault().heartbeatTimeoutMs()) {
            reject("it ran no cycle for " + silentMs + " ms (heartbeat timeout "
                    + next.contract.fault().heartbeatTimeoutMs() + " ms)");
            return;
        }
        if (cycles >= update.shadow()) {
            if (!update.tolerances().isEmpty() && compared == 0) {
                reject("no value of the same source cycle of both versions could be compared in " + cycles
                        + " cycles (tolerances " + update.tolerances() + ")");
                return;
            }
            done = true;
            StringBuilder sb = new StringBuilder(String.format(Locale.ROOT, "passed its shadow run of %d cycles "
                    + "(%d overruns or deadline misses, the running version %d; %d values compared", cycles, newBad,
                    oldBad, compared));
            for (int i = 0; i < largest.length; i++) {
                ChangeSet.Tolerance t = update.tolerances().get(i);
                sb.append(String.format(Locale.ROOT, ", %s.%s at most %s from the running version's (tolerance %s)",
                        t.port(), t.field(), largest[i] == 0 ? "0" : String.format(Locale.ROOT, "%.3g", largest[i]),
                        t.abs()));
            }
            sb.append(')');
            cell.monitor().unwatch(nextHalf); // watched again as the component's half at the switch
            publish(cycles, newBad);
            outcome.passed(this, sb.toString());
            return;
        }
        if (now - tEndMs >= 0) {
            reject(String.format(Locale.ROOT, "it ran only %d of its %d shadow cycles in %d ms", cycles,
                    update.shadow(), limitMs));
            return;
        }
        if (cycles != before) {
            publish(cycles, newBad);
        }
        timer = cell.actor().schedule(this::look, ChangeSetExecutor.WATCH_MS);
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

    /** The first declared field whose values differ beyond its tolerance, or null. */
    private String compare() {
        for (int k = 0; k < update.tolerances().size(); k++) {
            ChangeSet.Tolerance t = update.tolerances().get(k);
            RtLauncher.Output mine = next.outputs.get(t.port());
            RtLauncher.Output theirs = old.outputs.get(t.port());
            PortType type = type(next, t.port());
            if (mine == null || theirs == null || type == null || oldHalf.exit().isDone()) {
                continue;
            }
            PortType.Field stamp = type.field(STAMP).filter(f -> !f.padding() && f.count() == 1
                    && f.scalar().size() == 8).orElse(null);
            for (int attempt = 0; attempt < SAME_STAMP_ATTEMPTS; attempt++) {
                byte[] a;
                byte[] b;
                try {
                    a = theirs.newest(type.name(), (int) type.size());
                    b = mine.newest(type.name(), (int) type.size());
                } catch (IOException | RuntimeException e) {
                    break; // not readable now: the next look
                }
                if (a == null || b == null) {
                    break; // one has written nothing yet
                }
                ByteBuffer ba = ByteBuffer.wrap(a).order(ByteOrder.LITTLE_ENDIAN);
                ByteBuffer bb = ByteBuffer.wrap(b).order(ByteOrder.LITTLE_ENDIAN);
                long sa = stamp == null ? 0 : ba.getLong(stamp.offset());
                long sb = stamp == null ? 0 : bb.getLong(stamp.offset());
                if (sa != sb) {
                    continue; // another source cycle: read both again
                }
                compared++;
                double[] va = values(type, ba, t.field());
                double[] vb = values(type, bb, t.field());
                for (int i = 0; i < va.length && i < vb.length; i++) {
                    double d = Math.abs(vb[i] - va[i]);
                    boolean same = Double.compare(va[i], vb[i]) == 0;
                    if (!same && !(d <= t.abs())) {
                        return String.format(Locale.ROOT, "output %s.%s%s = %s differs from the running version's %s "
                                + "by %.3g%s, beyond its tolerance %s", t.port(), t.field(),
                                va.length > 1 ? "[" + i + "]" : "", vb[i], va[i], d,
                                stamp == null ? " (newest against newest)" : " (the same source cycle, " + STAMP + " " + sa + ")",
                                t.abs());
                    }
                    if (!same) {
                        largest[k] = Math.max(largest[k], d);
                    }
                }
                break;
            }
        }
        return null;
    }

    private static double[] values(PortType type, ByteBuffer b, String field) {
        for (PortFieldDTO f : PortValues.decode(type, b)) {
            if (f.name.equals(field)) {
                return f.values;
            }
        }
        return new double[0];
    }

    /** The port type of output {@code port} of {@code inst}, or null. */
    PortType type(Instance inst, String port) {
        PortSpec spec = inst.contract.outputs().stream().filter(p -> p.name().equals(port)).findFirst().orElse(null);
        return spec == null ? null : cell.config().types().find(spec.type()).orElse(null);
    }
}
