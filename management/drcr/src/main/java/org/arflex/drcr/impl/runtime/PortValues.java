package org.arflex.drcr.impl.runtime;

import java.io.IOException;
import java.nio.ByteBuffer;
import java.nio.ByteOrder;
import java.util.ArrayList;
import java.util.List;
import org.arflex.contract.PortSpec;
import org.arflex.contract.PortType;
import org.arflex.drcr.dto.PortFieldDTO;
import org.arflex.drcr.dto.PortValueDTO;
import org.arflex.drcr.impl.abi.PortReader;
import org.arflex.drcr.impl.supervisor.RtLauncher;

/**
 * Values of output ports for monitoring (the web console's live plots): where a port's segment
 * is (looked up on the actor thread) and its newest value, read off the actor thread from a
 * read-only mapping and decoded with the port type's field list.
 */
public final class PortValues {

    /** An output port of an instance: its contract entry, type and segment (null until created). */
    public record Ref(String component, PortSpec spec, PortType type, String segment) {
    }

    private PortValues() {
    }

    /**
     * Looks up output {@code port} of {@code name}; actor thread only.
     *
     * @throws IllegalArgumentException naming the component or port when there is no such output
     */
    public static Ref ref(Cell cell, String name, String port) {
        cell.actor().checkThread();
        Instance inst = cell.require(name);
        PortSpec p = inst.contract.outputs().stream().filter(o -> o.name().equals(port)).findFirst()
                .orElseThrow(() -> new IllegalArgumentException("component '" + name + "' has no output port '" + port
                        + "' (outputs: " + inst.contract.outputs().stream().map(PortSpec::name).toList() + ")"));
        PortType t = cell.config().types().find(p.type()).orElseThrow(() -> new IllegalArgumentException(
                "output " + name + "." + port + ": port type " + p.type() + " is not known to this runtime"));
        RtLauncher.Output o = inst.outputs.get(port);
        return new Ref(name, p, t, o == null ? null : o.name());
    }

    /**
     * Looks up the evaluation-only output {@code port} of {@code name} (the simulator's
     * {@code truth}, {@link EvaluationSegments}); actor thread only.
     *
     * @return the port, or null when the instance does not exist or has no such segment (not an
     *         evaluation run, not a simulated robot)
     */
    public static Ref evaluationRef(Cell cell, String name, String port) {
        cell.actor().checkThread();
        Instance inst = cell.find(name);
        RtLauncher.Output o = inst == null || !EvaluationSegments.PORT.equals(port) ? null : inst.evaluationOutputs.get(port);
        return o == null ? null : new Ref(name, EvaluationSegments.TRUTH_SPEC, EvaluationSegments.TRUTH_TYPE, o.name());
    }

    /**
     * Reads and decodes the newest value; any thread.
     *
     * @throws IllegalStateException naming the segment when it cannot be read
     */
    public static PortValueDTO read(Ref r, long nowNs) {
        PortValueDTO d = new PortValueDTO();
        d.component = r.component();
        d.port = r.spec().name();
        d.type = r.type().name();
        d.typeVersion = r.spec().typeVersion().toString();
        d.method = r.spec().method().name();
        d.fields = new PortFieldDTO[0];
        if (r.segment() != null) {
            PortReader.Value v;
            try {
                v = PortReader.readNewest(r.segment(), r.type().name(), r.type().size());
            } catch (IOException e) {
                throw new IllegalStateException(e.getMessage(), e);
            }
            d.published = v.published();
            if (v.index() >= 0) {
                d.index = v.index();
                d.stampNs = v.stampNs();
                d.fields = decode(r.type(), ByteBuffer.wrap(v.payload()).order(ByteOrder.LITTLE_ENDIAN));
            }
        }
        d.readNs = nowNs;
        return d;
    }

    /** Every non-pad field of one value of {@code t} starting at byte 0 of {@code b}. */
    static PortFieldDTO[] decode(PortType t, ByteBuffer b) {
        List<PortFieldDTO> out = new ArrayList<>();
        for (PortType.Field f : t.fields()) {
            if (f.padding()) {
                continue;
            }
            PortFieldDTO d = new PortFieldDTO();
            d.name = f.name();
            d.unit = f.unit() == null ? "" : f.unit();
            d.scalar = f.scalar().xmlName();
            d.count = f.count();
            int n = Math.min(f.count(), PortFieldDTO.MAX_VALUES);
            d.truncated = n < f.count();
            d.values = new double[n];
            for (int i = 0; i < n; i++) {
                int at = f.offset() + i * f.scalar().size();
                d.values[i] = switch (f.scalar()) {
                    case U8 -> b.get(at) & 0xff;
                    case U16 -> b.getShort(at) & 0xffff;
                    case U32 -> b.getInt(at) & 0xffffffffL;
                    case U64 -> unsigned(b.getLong(at));
                    case I32 -> b.getInt(at);
                    case I64 -> b.getLong(at);
                    case F32 -> b.getFloat(at);
                    case F64 -> b.getDouble(at);
                };
            }
            out.add(d);
        }
        return out.toArray(new PortFieldDTO[0]);
    }

    private static double unsigned(long v) {
        return v >= 0 ? v : (double) (v >>> 1) * 2.0 + (v & 1);
    }
}
