package org.arflex.drcr.impl.runtime;

import java.io.IOException;
import java.nio.ByteBuffer;
import java.nio.ByteOrder;
import java.util.List;
import java.util.Locale;
import org.arflex.contract.PortType;
import org.arflex.drcr.dto.PortFieldDTO;
import org.arflex.drcr.impl.supervisor.RtLauncher;

/**
 * An update's envelopes (D38): the bounds its new version's outputs must keep, checked in its
 * shadow run (D42) and in its rollback window.
 */
final class Envelopes {

    private Envelopes() {
    }

    /** Which newest value of {@code next}'s outputs lies outside its envelope, or null. */
    static String outside(Cell cell, Instance next, List<ChangeSet.Envelope> envelopes) {
        for (ChangeSet.Envelope e : envelopes) {
            RtLauncher.Output o = next.outputs.get(e.port());
            PortType t = UpdateOutputs.type(cell, next, e.port());
            if (o == null || t == null) {
                continue;
            }
            byte[] v;
            try {
                v = o.newest(t.name(), (int) t.size());
            } catch (IOException | RuntimeException ex) {
                continue; // not readable now: the next look
            }
            if (v == null) {
                continue;
            }
            for (PortFieldDTO f : PortValues.decode(t, ByteBuffer.wrap(v).order(ByteOrder.LITTLE_ENDIAN))) {
                if (!f.name.equals(e.field())) {
                    continue;
                }
                for (int i = 0; i < f.values.length; i++) {
                    double x = f.values[i];
                    if (!(x >= e.min() && x <= e.max())) {
                        return String.format(Locale.ROOT, "output %s.%s%s = %s left the envelope [%s, %s] "
                                + "declared for the update", e.port(), e.field(), f.count > 1 ? "[" + i + "]" : "",
                                x, e.min(), e.max());
                    }
                }
            }
        }
        return null;
    }
}
