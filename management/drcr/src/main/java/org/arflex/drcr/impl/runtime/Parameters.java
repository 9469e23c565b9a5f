package org.arflex.drcr.impl.runtime;

import java.io.IOException;
import java.util.List;
import org.arflex.contract.Contract;
import org.arflex.contract.PropertySpec;
import org.arflex.drcr.impl.supervisor.RtHalf;

/**
 * Reading and setting an instance's parameters: in its running RT half's control block, and in
 * the configured values its next start writes there ({@link Params} parses, checks and formats).
 */
final class Parameters {

    private Parameters() {
    }

    /**
     * Sets a parameter with type, range and mutability checks (actor thread); returns the applied value.
     *
     * @throws IllegalArgumentException naming the parameter and what is wrong
     */
    static String set(Instance inst, String param, String text) {
        String name = inst.name;
        Contract c = inst.contract;
        int idx = index(inst, param);
        PropertySpec p = c.properties().get(idx);
        long bits = Params.parse(p, text);
        RtHalf half = inst.half;
        if ((half != null || inst.launching) && !p.mutable()) {
            throw new IllegalArgumentException(name + "." + param + " is immutable while " + inst.life.state()
                    + " (mutable=false)");
        }
        long applied = bits;
        if (half != null) {
            try {
                applied = half.setParam(idx, bits);
            } catch (IOException e) {
                throw new IllegalStateException(name + "." + param + ": " + e.getMessage());
            }
            applied = half.paramValue(idx);
        }
        long[] v = inst.params.clone();
        v[idx] = applied;
        inst.params = v;
        return Params.format(p, applied);
    }

    /**
     * Checks what {@link #set} would: the name, the value's type and range and, when the half
     * will be running ({@code running}), the mutability. Changes nothing.
     *
     * @throws IllegalArgumentException as {@link #set}
     */
    static void check(Instance inst, String param, String text, boolean running) {
        PropertySpec p = inst.contract.properties().get(index(inst, param));
        Params.parse(p, text);
        if ((running || inst.half != null || inst.launching) && !p.mutable()) {
            throw new IllegalArgumentException(inst.name + "." + param + " is immutable while it runs (mutable=false)");
        }
    }

    private static int index(Instance inst, String param) {
        Contract c = inst.contract;
        for (int i = 0; i < c.properties().size(); i++) {
            if (c.properties().get(i).name().equals(param)) {
                return i;
            }
        }
        throw new IllegalArgumentException(inst.name + ": no parameter '" + param + "' (has "
                + c.properties().stream().map(PropertySpec::name).toList() + ")");
    }

    /** Reads a parameter as applied (control block when running, configuration otherwise). */
    static String get(Instance inst, String param) {
        List<PropertySpec> props = inst.contract.properties();
        for (int i = 0; i < props.size(); i++) {
            if (props.get(i).name().equals(param)) {
                RtHalf half = inst.half;
                long bits = half != null ? half.paramValue(i) : inst.params[i];
                return Params.format(props.get(i), bits);
            }
        }
        throw new IllegalArgumentException(inst.name + ": no parameter '" + param + "'");
    }
}
