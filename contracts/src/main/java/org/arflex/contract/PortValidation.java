package org.arflex.contract;

import static org.arflex.contract.ContractValidator.COMPONENT_NAME;
import static org.arflex.contract.ContractValidator.PORT_NAME;
import static org.arflex.contract.ContractValidator.TYPE_VERSION;
import static org.arflex.contract.ContractValidator.SAFETY_TYPE;
import static org.arflex.contract.ContractValidator.MAX_STREAM_DEPTH;
import static org.arflex.contract.ContractValidator.MAX_FRAME_DEPTH;
import static org.arflex.contract.ContractValidator.bool;

import java.util.Locale;
import java.util.Optional;
import java.util.Set;
import java.util.TreeSet;
import org.arflex.contract.internal.ContractXml;

/**
 * SPEC §6: checks one {@code <in>} / {@code <out>} port of a contract and its {@code <bind>} rule;
 * called by {@link ContractValidator}, reports into its {@link Problems}.
 */
final class PortValidation {
    private final PortTypes types;

    PortValidation(PortTypes types) {
        this.types = types;
    }

    PortSpec check(Problems p, ContractXml.Port x, Set<String> seen) {
        String kind = x.out ? "out" : "in";
        String f = "ports/" + kind + "[" + (x.name == null ? "?" : x.name) + "]";
        boolean ok = true;
        if (x.name == null) {
            p.at(x, "6.1", f + "/@name", "required attribute is missing");
            ok = false;
        } else if (!PORT_NAME.matcher(x.name).matches()) {
            p.at(x, "6.1", f + "/@name", "'" + x.name + "' is not a port name ([a-z][a-z0-9_]{0,31})");
            ok = false;
        } else if (!seen.add(x.name)) {
            p.at(x, "6.1", f + "/@name", "duplicate port name '" + x.name + "' (in and out share one name space)");
            ok = false;
        }
        PortType type = null;
        if (x.type == null) {
            p.at(x, "6.2", f + "/@type", "required attribute is missing");
            ok = false;
        } else if (!PortTypes.TYPE_NAME.matcher(x.type).matches()) {
            p.at(x, "6.2", f + "/@type", "'" + x.type + "' is not a port type name (namespace.TypeName)");
            ok = false;
        } else if (x.type.startsWith(PortTypes.EVAL_NAMESPACE)) {
            p.at(x, "6.7", f + "/@type", "'" + x.type + "': evaluation-only type, not bindable by components");
            ok = false;
        } else {
            type = types.find(x.type).orElse(null);
            if (type == null) {
                p.at(x, "6.2", f + "/@type", "unknown port type '" + x.type + "'; known types: "
                        + types.all().stream().map(PortType::name).toList());
                ok = false;
            }
        }
        TypeVersion tv = null;
        if (x.typeVersion == null) {
            p.at(x, "6.2", f + "/@typeVersion", "required attribute is missing");
            ok = false;
        } else if (!TYPE_VERSION.matcher(x.typeVersion).matches()) {
            p.at(x, "6.2", f + "/@typeVersion", "'" + x.typeVersion + "' is not MAJOR.MINOR (e.g. 1.0)");
            ok = false;
        } else {
            tv = TypeVersion.parse(x.typeVersion);
            if (type != null && !type.version().canFeed(tv)) {
                p.at(x, "6.2", f + "/@typeVersion", "version mismatch: the contract is built against " + x.type + " "
                        + tv + " but the known definition is " + type.version() + " (needs major " + tv.major()
                        + " and minor >= " + tv.minor() + ")");
                ok = false;
            }
        }
        PortSpec.Method method = null;
        if (x.method == null) {
            p.at(x, "6.3", f + "/@method", "required attribute is missing (state, stream or frame)");
            ok = false;
        } else {
            method = switch (x.method) {
                case "state" -> PortSpec.Method.STATE;
                case "stream" -> PortSpec.Method.STREAM;
                case "frame" -> PortSpec.Method.FRAME;
                default -> null;
            };
            if (method == null) {
                p.at(x, "6.3", f + "/@method", "'" + x.method + "' is not a method (state, stream or frame)");
                ok = false;
            } else if (type != null && !type.methods().contains(method)) {
                p.at(x, "6.3", f + "/@method", "method mismatch: " + type.name() + " allows "
                        + new TreeSet<>(type.methods().stream().map(m -> m.name().toLowerCase(Locale.ROOT)).toList())
                        + ", not " + x.method);
                ok = false;
            }
        }
        int depth = 1;
        PortSpec.Overflow overflow = PortSpec.Overflow.DROP_OLDEST;
        boolean optional = false;
        boolean safety = false;
        Optional<Binding> binding = Optional.empty();
        if (x.out) {
            if (x.optional != null) {
                p.at(x, "6.4", f + "/@optional", "only an in port may be optional");
                ok = false;
            }
            if (x.safety != null) {
                p.at(x, "6.8", f + "/@safety", "only an in port is a safety input; a guard's output is an ordinary "
                        + SAFETY_TYPE + " output");
                ok = false;
            }
            if (!x.binds.isEmpty()) {
                p.at(x.binds.get(0), "6.5", f + "/bind", "a binding refers to an in port only; outputs are chosen by their consumers");
                ok = false;
            }
            if (method != null) {
                if (x.depth == null) {
                    if (method != PortSpec.Method.STATE) {
                        p.at(x, "6.4", f + "/@depth", "required for a " + x.method + " output (ring depth in slots)");
                        ok = false;
                    }
                } else {
                    Integer d = Values.integer(x.depth);
                    int max = method == PortSpec.Method.STREAM ? MAX_STREAM_DEPTH
                            : method == PortSpec.Method.FRAME ? MAX_FRAME_DEPTH : 1;
                    if (d == null) {
                        p.at(x, "6.4", f + "/@depth", "'" + x.depth + "' is not an integer");
                        ok = false;
                    } else if (d < 1 || d > max) {
                        p.at(x, "6.4", f + "/@depth", "depth " + d + " is out of range 1.." + max + " for a " + x.method
                                + " output");
                        ok = false;
                    } else {
                        depth = d;
                    }
                }
                if (x.overflow != null) {
                    if (method != PortSpec.Method.STREAM) {
                        p.at(x, "6.4", f + "/@overflow", "only a stream output has an overflow policy");
                        ok = false;
                    } else if ("drop-oldest".equals(x.overflow)) {
                        overflow = PortSpec.Overflow.DROP_OLDEST;
                    } else if ("drop-newest".equals(x.overflow)) {
                        overflow = PortSpec.Overflow.DROP_NEWEST;
                    } else {
                        p.at(x, "6.4", f + "/@overflow", "'" + x.overflow + "' is not drop-oldest or drop-newest");
                        ok = false;
                    }
                }
            }
        } else {
            if (x.depth != null) {
                p.at(x, "6.4", f + "/@depth", "only an out port has a depth; the provider's output sets it");
                ok = false;
            }
            if (x.overflow != null) {
                p.at(x, "6.4", f + "/@overflow", "only an out port has an overflow policy");
                ok = false;
            }
            optional = bool(p, x, x.optional, false, "6.5", f + "/@optional");
            safety = bool(p, x, x.safety, false, "6.8", f + "/@safety");
            if (safety && x.type != null && !SAFETY_TYPE.equals(x.type)) {
                p.at(x, "6.8", f + "/@safety", "a safety input carries " + SAFETY_TYPE + ", not " + x.type);
                ok = false;
            }
            if (safety && x.optional != null && !optional) {
                p.at(x, "6.8", f + "/@optional", "a safety input is never required to start: the component starts "
                        + "without a guard and holds in a protective stop; leave optional out");
                ok = false;
            }
            // A safety input does not keep its component from starting: it holds without one.
            optional |= safety;
            if (x.binds.size() > 1) {
                p.at(x.binds.get(1), "6.5", f + "/bind", "an input has at most one <bind>");
                ok = false;
            } else if (x.binds.size() == 1) {
                binding = bind(p, x.binds.get(0), f);
                ok &= binding.isPresent();
            }
        }
        if (!ok || type == null || tv == null || method == null) {
            return null;
        }
        return new PortSpec(x.name, x.out ? PortSpec.Direction.OUT : PortSpec.Direction.IN, x.type, tv, method, depth,
                overflow, binding, optional, safety);
    }

    private Optional<Binding> bind(Problems p, ContractXml.Bind b, String portField) {
        String f = portField + "/bind";
        if (b.filter != null) {
            if (b.component != null || b.port != null) {
                p.at(b, "6.5", f, "a binding is either component+port or filter, not both");
                return Optional.empty();
            }
            try {
                Filter.parse(b.filter);
                return Optional.of(Binding.filter(b.filter));
            } catch (Filter.SyntaxException e) {
                p.at(b, "6.6", f + "/@filter", "bad filter '" + b.filter + "': " + e.getMessage());
                return Optional.empty();
            }
        }
        boolean ok = true;
        if (b.component == null || b.port == null) {
            p.at(b, "6.5", f, "an explicit binding needs both component and port (or use filter)");
            return Optional.empty();
        }
        if (!COMPONENT_NAME.matcher(b.component).matches()) {
            p.at(b, "6.5", f + "/@component", "'" + b.component + "' is not a component name ([a-z][a-z0-9-]{0,47})");
            ok = false;
        }
        if (!PORT_NAME.matcher(b.port).matches()) {
            p.at(b, "6.5", f + "/@port", "'" + b.port + "' is not a port name ([a-z][a-z0-9_]{0,31})");
            ok = false;
        }
        return ok ? Optional.of(Binding.explicit(b.component, b.port)) : Optional.empty();
    }
}
