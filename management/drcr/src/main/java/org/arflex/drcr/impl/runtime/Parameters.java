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
        int idx = -1;
        for (int i = 0; i < c.properties().size(); i++) {
            if (c.properties().get(i).name().equals(param)) {
                idx = i;
            }
        }
        if (idx < 0) {
            throw new IllegalArgumentException(name + ": no parameter '" + param + "' (has "
                    + c.properties().stream().map(PropertySpec::name).toList() + ")");
        }
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
