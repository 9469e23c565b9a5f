package org.arflex.contract;

import java.util.ArrayList;
import java.util.List;
import java.util.Locale;
import java.util.Optional;
import org.arflex.contract.internal.ContractXml;

/**
 * SPEC §12.1 (docs/DECISIONS.md D41): checks a contract's {@code <state type typeVersion>} block and its
 * {@code <convertsFrom>} children; called by {@link ContractValidator}, reports into its {@link Problems}.
 */
final class StateValidation {
    private final PortTypes types;

    StateValidation(PortTypes types) {
        this.types = types;
    }

    /** The state block's type (known, a state type), its version and the conversions it declares. */
    Optional<StateSpec> check(Problems p, ContractXml.StateXml x) {
        boolean ok = true;
        PortType type = null;
        if (x.type == null) {
            p.at(x, "12.1", "state/@type", "required attribute is missing (a port type, e.g. arflex.TrajectoryState)");
            ok = false;
        } else if (!PortTypes.TYPE_NAME.matcher(x.type).matches()) {
            p.at(x, "12.1", "state/@type", "'" + x.type + "' is not a port type name (namespace.TypeName)");
            ok = false;
        } else {
            type = types.find(x.type).orElse(null);
            if (type == null) {
                p.at(x, "12.1", "state/@type", "unknown port type '" + x.type + "'; known types: "
                        + types.all().stream().map(PortType::name).toList());
                ok = false;
            } else if (!type.methods().contains(PortSpec.Method.STATE)) {
                p.at(x, "12.1", "state/@type", "port type " + x.type + " does not allow the state method (it allows "
                        + type.methods().stream().map(m -> m.name().toLowerCase(Locale.ROOT)).sorted().toList() + ")");
                ok = false;
            }
        }
        TypeVersion tv = null;
        if (x.typeVersion == null) {
            p.at(x, "12.1", "state/@typeVersion", "required attribute is missing");
            ok = false;
        } else if (!ContractValidator.TYPE_VERSION.matcher(x.typeVersion).matches()) {
            p.at(x, "12.1", "state/@typeVersion", "'" + x.typeVersion + "' is not MAJOR.MINOR (e.g. 1.0)");
            ok = false;
        } else {
            tv = TypeVersion.parse(x.typeVersion);
            if (type != null && !type.version().canFeed(tv)) {
                p.at(x, "12.1", "state/@typeVersion", "version mismatch: the contract is built against " + x.type + " "
                        + tv + " but the known definition is " + type.version() + " (needs major " + tv.major()
                        + " and minor >= " + tv.minor() + ")");
                ok = false;
            }
        }
        List<StateSpec.From> froms = new ArrayList<>();
        for (ContractXml.From f : x.convertsFrom) {
            String at = "state/convertsFrom[" + (f.type == null ? "" : f.type) + "]";
            boolean fine = true;
            if (f.type == null) {
                p.at(f, "12.1", at + "/@type", "required attribute is missing");
                fine = false;
            } else if (!PortTypes.TYPE_NAME.matcher(f.type).matches()) {
                p.at(f, "12.1", at + "/@type", "'" + f.type + "' is not a port type name (namespace.TypeName)");
                fine = false;
            }
            if (f.typeVersion == null) {
                p.at(f, "12.1", at + "/@typeVersion", "required attribute is missing");
                fine = false;
            } else if (!ContractValidator.TYPE_VERSION.matcher(f.typeVersion).matches()) {
                p.at(f, "12.1", at + "/@typeVersion", "'" + f.typeVersion + "' is not MAJOR.MINOR (e.g. 1.0)");
                fine = false;
            }
            if (!fine) {
                ok = false;
                continue;
            }
            StateSpec.From from = new StateSpec.From(f.type, TypeVersion.parse(f.typeVersion));
            if (froms.contains(from)) {
                p.at(f, "12.1", at, "conversion from " + from + " is declared twice");
                ok = false;
            } else if (tv != null && from.type().equals(x.type) && from.typeVersion().canFeed(tv)) {
                p.at(f, "12.1", at, "no conversion needed: " + from + " is adopted as it is (same type, a version that "
                        + "feeds " + tv + ")");
                ok = false;
            }
            froms.add(from);
        }
        return ok ? Optional.of(new StateSpec(x.type, tv, froms)) : Optional.empty();
    }
}
