package org.arflex.contract;

import static org.arflex.contract.ContractValidator.MAX_MEMORY;

import org.arflex.contract.internal.ContractXml;

/**
 * SPEC §9: checks a contract's {@code <resources>} (memory size and range, network rate);
 * called by {@link ContractValidator}, reports into its {@link Problems}.
 */
final class ResourceValidation {
    private ResourceValidation() {
    }

    static Resources check(Problems p, ContractXml x) {
        Resources resources = null;
        if (x.resources == null) {
            p.at(x, "9", "resources", "required element <resources> is missing");
        } else {
            ContractXml.ResourcesXml r = x.resources;
            Long mem = null;
            if (r.memory == null) {
                p.at(r, "9.2", "resources/@memory", "required attribute is missing");
            } else {
                mem = Values.size(r.memory);
                if (mem == null) {
                    p.at(r, "9.1", "resources/@memory", "'" + r.memory
                            + "' is not a size (integer with optional unit B, KiB, MiB, GiB, kB, MB, GB)");
                } else if (mem < 1 || mem > MAX_MEMORY) {
                    p.at(r, "9.2", "resources/@memory", "memory " + r.memory + " is out of range (1B..64GiB)");
                    mem = null;
                }
            }
            Long net = 0L;
            if (r.network != null) {
                net = Values.rate(r.network);
                if (net == null) {
                    p.at(r, "9.1", "resources/@network", "'" + r.network
                            + "' is not a rate (integer with optional unit B, KiB, MiB, GiB, kB, MB, GB and optional /s)");
                }
            }
            if (mem != null && net != null) {
                resources = new Resources(mem, net);
            }
        }
        return resources;
    }
}
