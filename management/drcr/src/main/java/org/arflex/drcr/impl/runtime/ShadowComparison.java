package org.arflex.drcr.impl.runtime;

import java.io.IOException;
import java.nio.ByteBuffer;
import java.nio.ByteOrder;
import java.util.List;
import java.util.Locale;
import org.arflex.contract.PortType;
import org.arflex.drcr.impl.supervisor.RtHalf;
import org.arflex.drcr.impl.supervisor.RtLauncher;

/**
 * The comparison of a shadow run's outputs with the running version's by the update's declared
 * tolerances (D42). Values are compared for the same source cycle: when the port type has a
 * field {@code t_ns} (the time its value is for, which a stage passes on from its input) the
 * newest value of each half is read until both carry the same stamp ({@link #SAME_STAMP_ATTEMPTS}
 * per look; a look that finds none compares nothing); a type without {@code t_ns} compares
 * newest with newest, so its tolerance must cover what one cycle changes. NaN equals NaN.
 * Keeps how many values it compared and the largest difference of each tolerance. Actor thread.
 */
final class ShadowComparison {

    /** Attempts per look to read both halves' values of one source cycle. */
    static final int SAME_STAMP_ATTEMPTS = 4;
    /** The field that carries a value's source time (when its type has one). */
    static final String STAMP = "t_ns";

    private final Cell cell;
    private final List<ChangeSet.Tolerance> tolerances;
    private final Instance old;
    private final RtHalf oldHalf;
    private final Instance next;
    /** Values of the same source cycle compared so far, and the largest difference of each tolerance. */
    private long compared;
    private final double[] largest;

    ShadowComparison(Cell cell, List<ChangeSet.Tolerance> tolerances, Instance old, RtHalf oldHalf, Instance next) {
        this.cell = cell;
        this.tolerances = tolerances;
        this.old = old;
        this.oldHalf = oldHalf;
        this.next = next;
        this.largest = new double[tolerances.size()];
    }

    /** Values of the same source cycle compared so far. */
    long compared() {
        return compared;
    }

    /** The largest difference of tolerance {@code k} so far. */
    double largest(int k) {
        return largest[k];
    }

    /** The index of the tolerance closest to being exceeded (its largest difference relative to it), or -1. */
    int worst() {
        int worst = -1;
        for (int i = 0; i < largest.length; i++) {
            if (worst < 0 || relative(i) > relative(worst)) {
                worst = i;
            }
        }
        return worst;
    }

    private double relative(int i) {
        double abs = tolerances.get(i).abs();
        return abs > 0 ? largest[i] / abs : largest[i];
    }

    /** The first declared field whose values differ beyond its tolerance, or null. */
    String compare() {
        for (int k = 0; k < tolerances.size(); k++) {
            ChangeSet.Tolerance t = tolerances.get(k);
            RtLauncher.Output mine = next.outputs.get(t.port());
            RtLauncher.Output theirs = old.outputs.get(t.port());
            PortType type = UpdateOutputs.type(cell, next, t.port());
            if (mine == null || theirs == null || type == null || oldHalf.exit().isDone()) {
                continue;
            }
            String differs = compare(k, t, type, mine, theirs);
            if (differs != null) {
                return differs;
            }
        }
        return null;
    }

    /** One look at tolerance {@code k}: its first value beyond it, or null. */
    private String compare(int k, ChangeSet.Tolerance t, PortType type, RtLauncher.Output mine,
                           RtLauncher.Output theirs) {
        PortType.Field stamp = type.field(STAMP).filter(f -> !f.padding() && f.count() == 1
                && f.scalar().size() == 8).orElse(null);
        for (int attempt = 0; attempt < SAME_STAMP_ATTEMPTS; attempt++) {
            byte[] a;
            byte[] b;
            try {
                a = theirs.newest(type.name(), (int) type.size());
                b = mine.newest(type.name(), (int) type.size());
            } catch (IOException | RuntimeException e) {
                return null; // not readable now: the next look
            }
            if (a == null || b == null) {
                return null; // one has written nothing yet
            }
            ByteBuffer ba = ByteBuffer.wrap(a).order(ByteOrder.LITTLE_ENDIAN);
            ByteBuffer bb = ByteBuffer.wrap(b).order(ByteOrder.LITTLE_ENDIAN);
            long sa = stamp == null ? 0 : ba.getLong(stamp.offset());
            long sb = stamp == null ? 0 : bb.getLong(stamp.offset());
            if (sa != sb) {
                continue; // another source cycle: read both again
            }
            compared++;
            double[] va = UpdateOutputs.values(type, ba, t.field());
            double[] vb = UpdateOutputs.values(type, bb, t.field());
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
            return null;
        }
        return null;
    }
}
