package org.arflex.drcr.impl.runtime;

import java.nio.ByteBuffer;
import org.arflex.contract.PortSpec;
import org.arflex.contract.PortType;
import org.arflex.drcr.dto.PortFieldDTO;

/**
 * Reading an update's output values (D38, D42): the port type of an output, and a field's
 * values decoded from a value read from its segment.
 */
final class UpdateOutputs {

    private UpdateOutputs() {
    }

    /** The port type of output {@code port} of {@code inst}, or null. */
    static PortType type(Cell cell, Instance inst, String port) {
        PortSpec spec = inst.contract.outputs().stream().filter(p -> p.name().equals(port)).findFirst().orElse(null);
        return spec == null ? null : cell.config().types().find(spec.type()).orElse(null);
    }

    /** The values of {@code field} in {@code b} (a value of {@code type}); none when it has no such field. */
    static double[] values(PortType type, ByteBuffer b, String field) {
        for (PortFieldDTO f : PortValues.decode(type, b)) {
            if (f.name.equals(field)) {
                return f.values;
            }
        }
        return new double[0];
    }
}
