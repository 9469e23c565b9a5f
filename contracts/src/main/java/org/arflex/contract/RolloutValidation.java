package org.arflex.contract;

import java.util.ArrayList;
import java.util.HashSet;
import java.util.List;
import java.util.Optional;
import java.util.OptionalLong;
import java.util.Set;
import org.arflex.contract.internal.ContractXml;

/**
 * SPEC §12.2 (docs/DECISIONS.md D42): checks a contract's {@code <rollout shadow window>} block with its
 * tolerances and envelopes on the outputs' numeric fields; called by {@link ContractValidator}, reports
 * into its {@link Problems}.
 */
final class RolloutValidation {
    private final PortTypes types;

    RolloutValidation(PortTypes types) {
        this.types = types;
    }

    /** The shadow run's and the window's cycles, and rules on the outputs' numeric fields. */
    Optional<RolloutSpec> check(Problems p, ContractXml.Rollout r, List<PortSpec> ports) {
        boolean ok = true;
        OptionalLong shadow = OptionalLong.empty();
        OptionalLong window = OptionalLong.empty();
        for (String[] a : new String[][] {{"shadow", r.shadow}, {"window", r.window}}) {
            if (a[1] == null) {
                continue;
            }
            Long n = Values.longValue(a[1].trim());
            if (n == null || n < 0 || n > RolloutSpec.MAX_CYCLES) {
                p.at(r, "12.2", "rollout/@" + a[0], "'" + a[1] + "' is not a number of cycles (an integer 0.."
                        + RolloutSpec.MAX_CYCLES + ")");
                ok = false;
            } else if (a[0].equals("shadow")) {
                shadow = OptionalLong.of(n);
            } else {
                window = OptionalLong.of(n);
            }
        }
        List<RolloutSpec.Tolerance> tolerances = new ArrayList<>();
        Set<String> seen = new HashSet<>();
        for (ContractXml.OutputRule t : r.tolerances) {
            String f = "rollout/tolerance[" + t.port + "." + t.field + "]";
            boolean good = outputField(p, t, ports, f);
            if (good && !seen.add(t.port + "." + t.field)) {
                p.at(t, "12.2", f, "a second tolerance for " + t.port + "." + t.field);
                good = false;
            }
            Double abs = t.abs == null ? null : Values.decimal(t.abs.trim());
            if (t.abs == null) {
                p.at(t, "12.2", f + "/@abs", "required attribute is missing (the largest difference, >= 0)");
                good = false;
            } else if (abs == null || !Double.isFinite(abs) || abs < 0) {
                p.at(t, "12.2", f + "/@abs", "'" + t.abs + "' is not a tolerance (a finite number >= 0)");
                good = false;
            }
            if (good) {
                tolerances.add(new RolloutSpec.Tolerance(t.port, t.field, abs));
            }
            ok &= good;
        }
        List<RolloutSpec.Envelope> envelopes = new ArrayList<>();
        for (ContractXml.OutputRule e : r.envelopes) {
            String f = "rollout/envelope[" + e.port + "." + e.field + "]";
            boolean good = outputField(p, e, ports, f);
            Double min = e.min == null ? null : Values.decimal(e.min.trim());
            Double max = e.max == null ? null : Values.decimal(e.max.trim());
            for (String[] a : new String[][] {{"min", e.min}, {"max", e.max}}) {
                if (a[1] == null) {
                    p.at(e, "12.2", f + "/@" + a[0], "required attribute is missing (a number)");
                    good = false;
                } else if (Values.decimal(a[1].trim()) == null || !Double.isFinite(Values.decimal(a[1].trim()))) {
                    p.at(e, "12.2", f + "/@" + a[0], "'" + a[1] + "' is not a finite number");
                    good = false;
                }
            }
            if (good && !(min <= max)) {
                p.at(e, "12.2", f, "min " + e.min + " is greater than max " + e.max);
                good = false;
            }
            if (good) {
                envelopes.add(new RolloutSpec.Envelope(e.port, e.field, min, max));
            }
            ok &= good;
        }
        return ok ? Optional.of(new RolloutSpec(shadow, window, tolerances, envelopes)) : Optional.empty();
    }

    /** The rule names an output of this contract and a numeric field of its port type. */
    private boolean outputField(Problems p, ContractXml.OutputRule r, List<PortSpec> ports, String f) {
        if (r.port == null || r.field == null) {
            p.at(r, "12.2", f + (r.port == null ? "/@port" : "/@field"), "required attribute is missing");
            return false;
        }
        PortSpec out = ports.stream().filter(q -> q.name().equals(r.port)).findFirst().orElse(null);
        if (out == null || out.direction() != PortSpec.Direction.OUT) {
            p.at(r, "12.2", f + "/@port", out == null ? "no output '" + r.port + "' is declared (ports/out)"
                    : "'" + r.port + "' is an input; only outputs are compared");
            return false;
        }
        PortType type = types.find(out.type()).orElse(null);
        if (type == null) {
            return false; // reported under §6.2
        }
        PortType.Field fd = type.field(r.field).orElse(null);
        if (fd == null || fd.padding()) {
            p.at(r, "12.2", f + "/@field", "port type " + type.name() + " has no field '" + r.field + "'; its fields: "
                    + type.fields().stream().filter(x -> !x.padding()).map(PortType.Field::name).toList());
            return false;
        }
        if (fd.scalar() == PortType.Scalar.U8 && fd.count() > 1) {
            p.at(r, "12.2", f + "/@field", "field '" + r.field + "' of " + type.name() + " is bytes (u8["
                    + fd.count() + "]), not a numeric value");
            return false;
        }
        return true;
    }
}
