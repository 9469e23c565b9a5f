package org.arflex.contract;

import java.net.URI;
import java.net.URISyntaxException;
import java.util.ArrayList;
import java.util.HashSet;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Locale;
import java.util.Map;
import java.util.Optional;
import java.util.Set;
import java.util.TreeSet;
import java.util.regex.Pattern;
import org.arflex.contract.internal.ContractXml;
import org.arflex.contract.internal.Located;

/**
 * Checks a bound contract against every rule of contracts/SPEC.md and freezes it into the
 * immutable {@link Contract}. Reports all problems it finds, each citing its section; returns
 * null when there was any.
 */
final class ContractValidator {
    static final Pattern COMPONENT_NAME = Pattern.compile("[a-z][a-z0-9-]{0,47}");
    static final Pattern SEMVER = Pattern.compile(
            "(0|[1-9][0-9]{0,8})\\.(0|[1-9][0-9]{0,8})\\.(0|[1-9][0-9]{0,8})(-[0-9A-Za-z-]+(\\.[0-9A-Za-z-]+)*)?");
    static final Pattern EXECUTABLE = Pattern.compile("[A-Za-z0-9][A-Za-z0-9_.-]{0,63}");
    static final Pattern ATTRIBUTE_NAME = Pattern.compile("[A-Za-z][A-Za-z0-9_.-]{0,63}");
    static final Pattern PORT_NAME = Pattern.compile("[a-z][a-z0-9_]{0,31}");
    static final Pattern PROPERTY_NAME = Pattern.compile("[a-z][a-z0-9_.]{0,30}");
    static final Pattern TYPE_VERSION = Pattern.compile("(0|[1-9][0-9]{0,4})\\.(0|[1-9][0-9]{0,4})");
    static final Pattern UNIT = Pattern.compile("[\\p{L}\\p{N}/^*.%·_°-]{0,16}");
    static final Pattern SHA256 = Pattern.compile("[0-9a-fA-F]{64}");
    /** The port type of a safety input (§6.8). */
    static final String SAFETY_TYPE = "arflex.SafetyState";
    static final Pattern CPUS = Pattern.compile("[0-9]{1,4}(-[0-9]{1,4})?(,[0-9]{1,4}(-[0-9]{1,4})?)*");

    static final int MAX_ATTRIBUTE_VALUE = 256;
    static final int MAX_STREAM_DEPTH = 65536;
    static final int MAX_FRAME_DEPTH = 256;
    static final int MAX_CPU = 1023;
    static final long MAX_PERIOD_NS = 60_000_000_000L;
    static final long MAX_MEMORY = 64L << 30;
    static final int MAX_CRITICALITY = 100;
    static final int MAX_INTENSITY = 1000;

    private final PortTypes types;
    private final StateValidation stateValidation;
    private final RolloutValidation rolloutValidation;

    ContractValidator(PortTypes types) {
        this.types = types;
        this.stateValidation = new StateValidation(types);
        this.rolloutValidation = new RolloutValidation(types);
    }

    Contract freeze(ContractXml x, String source, List<Problem> out) {
        Problems p = new Problems(source, out);
        for (String d : x.duplicates) {
            p.at(x, "2.4", d, "element <" + d + "> may appear only once");
        }

        // §3 identity
        String name = x.name;
        if (name == null) {
            p.at(x, "3.1", "component/@name", "required attribute is missing");
        } else if (!COMPONENT_NAME.matcher(name).matches()) {
            p.at(x, "3.1", "component/@name", "'" + name + "' is not a component name ([a-z][a-z0-9-]{0,47})");
        }
        if (x.version == null) {
            p.at(x, "3.2", "component/@version", "required attribute is missing");
        } else if (!SEMVER.matcher(x.version).matches()) {
            p.at(x, "3.2", "component/@version", "'" + x.version + "' is not a semantic version MAJOR.MINOR.PATCH[-pre]");
        }
        String description = "";
        if (x.description != null) {
            if (x.description.structured) {
                p.at(x.description, "3.3", "description", "must be plain text (no attributes or child elements)");
            }
            description = Values.text(x.description.value);
        }

        // §4 implementation
        String executable = null;
        Contract.TaskType task = null;
        boolean moves = false;
        boolean throughOutputs = false;
        ContractXml.Impl impl = x.implementation;
        if (impl == null) {
            p.at(x, "4", "implementation", "required element <implementation> is missing");
        } else {
            executable = impl.executable;
            if (executable == null) {
                p.at(impl, "4.1", "implementation/@executable", "required attribute is missing");
            } else if (!EXECUTABLE.matcher(executable).matches() || executable.matches("\\.+")) {
                p.at(impl, "4.1", "implementation/@executable", "'" + executable
                        + "' is not an executable file name ([A-Za-z0-9][A-Za-z0-9_.-]{0,63}, no path)");
            }
            if (impl.task == null) {
                p.at(impl, "4.2", "implementation/@task", "required attribute is missing (periodic, sporadic or service)");
            } else {
                task = switch (impl.task) {
                    case "periodic" -> Contract.TaskType.PERIODIC;
                    case "sporadic" -> Contract.TaskType.SPORADIC;
                    case "service" -> Contract.TaskType.SERVICE;
                    default -> {
                        p.at(impl, "4.2", "implementation/@task",
                                "'" + impl.task + "' is not a task type (periodic, sporadic or service)");
                        yield null;
                    }
                };
            }
            moves = bool(p, impl, impl.movesHardware, false, "4.3", "implementation/@movesHardware");
            if (impl.motionThrough != null) {
                if (!impl.motionThrough.equals("device") && !impl.motionThrough.equals("outputs")) {
                    p.at(impl, "4.3", "implementation/@motionThrough", "'" + impl.motionThrough
                            + "' is not where motion goes (device or outputs)");
                } else if (!moves) {
                    p.at(impl, "4.3", "implementation/@motionThrough", "only a component that moves hardware "
                            + "(movesHardware=\"true\") says where its motion goes");
                }
                throughOutputs = moves && impl.motionThrough.equals("outputs");
            }
        }

        // §5 attributes
        Map<String, String> attributes = new LinkedHashMap<>();
        if (x.attributes != null) {
            Set<String> seen = new HashSet<>();
            for (ContractXml.Attr a : x.attributes.list) {
                String f = "attributes/attribute[" + a.name + "]";
                boolean ok = true;
                if (a.name == null) {
                    p.at(a, "5", "attributes/attribute/@name", "required attribute is missing");
                    ok = false;
                } else if (!ATTRIBUTE_NAME.matcher(a.name).matches()) {
                    p.at(a, "5", f + "/@name", "'" + a.name + "' is not an attribute name ([A-Za-z][A-Za-z0-9_.-]{0,63})");
                    ok = false;
                } else if (!seen.add(a.name.toLowerCase(Locale.ROOT))) {
                    p.at(a, "5", f + "/@name", "duplicate attribute '" + a.name
                            + "' (names are compared ignoring case, as filters do)");
                    ok = false;
                }
                if (a.value == null) {
                    p.at(a, "5", f + "/@value", "required attribute is missing");
                    ok = false;
                } else if (a.value.length() > MAX_ATTRIBUTE_VALUE || a.value.chars().anyMatch(Character::isISOControl)) {
                    p.at(a, "5", f + "/@value", "value must be at most " + MAX_ATTRIBUTE_VALUE
                            + " characters without control characters");
                    ok = false;
                }
                if (ok) {
                    attributes.put(a.name, a.value);
                }
            }
        }

        // §6 ports
        List<PortSpec> ports = new ArrayList<>();
        if (x.ports != null) {
            Set<String> seen = new HashSet<>();
            for (ContractXml.Port port : x.ports.list) {
                PortSpec ps = port(p, port, seen);
                if (ps != null) {
                    ports.add(ps);
                }
            }
        }
        boolean guarded = x.ports != null && x.ports.list.stream()
                .anyMatch(q -> !q.out && q.safety != null && !"false".equals(q.safety));
        if (moves && !guarded) {
            p.at(x.implementation, "6.8", "implementation/@movesHardware", "a component that moves hardware declares the "
                    + "safety input that permits its motion: <in ... type=\"" + SAFETY_TYPE + "\" safety=\"true\">");
        }

        // §7 properties
        List<PropertySpec> properties = new ArrayList<>();
        if (x.properties != null) {
            Set<String> seen = new HashSet<>();
            for (ContractXml.Prop prop : x.properties.list) {
                PropertySpec ps = property(p, prop, seen);
                if (ps != null) {
                    properties.add(ps);
                }
            }
        }

        // §8 timing
        Timing timing = timing(p, x, task);

        // §9 resources
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

        // §10 criticality
        int criticality = -1;
        if (x.criticality == null) {
            p.at(x, "10", "criticality", "required element <criticality> is missing");
        } else if (x.criticality.structured) {
            p.at(x.criticality, "10", "criticality", "must be plain text (an integer 0..100)");
        } else {
            Integer c = Values.integer(x.criticality.value.trim());
            if (c == null) {
                p.at(x.criticality, "10", "criticality", "'" + x.criticality.value.trim() + "' is not an integer");
            } else if (c < 0 || c > MAX_CRITICALITY) {
                p.at(x.criticality, "10", "criticality", "criticality " + c + " is out of range 0..100");
            } else {
                criticality = c;
            }
        }

        // §11 fault policy
        FaultPolicy fault = fault(p, x, timing, task);

        // §12 update
        Optional<UpdateSpec> update = Optional.empty();
        if (x.update != null) {
            update = update(p, x.update);
        }

        // §12.1 state
        Optional<StateSpec> state = Optional.empty();
        if (x.state != null) {
            state = stateValidation.check(p, x.state);
        }

        // §12.2 rollout
        Optional<RolloutSpec> rollout = Optional.empty();
        if (x.rollout != null) {
            rollout = rolloutValidation.check(p, x.rollout, ports);
        }

        if (!p.clean()) {
            return null;
        }
        return new Contract(name, x.version, description, executable, task, moves, attributes, ports, properties,
                timing, resources, criticality, fault, update, source, state, rollout, throughOutputs);
    }

    private PortSpec port(Problems p, ContractXml.Port x, Set<String> seen) {
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

    private PropertySpec property(Problems p, ContractXml.Prop x, Set<String> seen) {
        String f = "properties/property[" + (x.name == null ? "?" : x.name) + "]";
        boolean ok = true;
        if (x.name == null) {
            p.at(x, "7.1", f + "/@name", "required attribute is missing");
            ok = false;
        } else if (!PROPERTY_NAME.matcher(x.name).matches()) {
            p.at(x, "7.1", f + "/@name", "'" + x.name + "' is not a property name ([a-z][a-z0-9_.]{0,30})");
            ok = false;
        } else if (!seen.add(x.name)) {
            p.at(x, "7.1", f + "/@name", "duplicate property name '" + x.name + "'");
            ok = false;
        }
        PropertySpec.Type type = null;
        if (x.type == null) {
            p.at(x, "7.2", f + "/@type", "required attribute is missing (bool, int or double)");
            return null;
        }
        switch (x.type) {
            case "bool" -> type = PropertySpec.Type.BOOL;
            case "int" -> type = PropertySpec.Type.INT;
            case "double" -> type = PropertySpec.Type.DOUBLE;
            default -> {
                p.at(x, "7.2", f + "/@type", "'" + x.type + "' is not a property type (bool, int or double)");
                return null;
            }
        }
        Optional<Double> min = Optional.empty();
        Optional<Double> max = Optional.empty();
        PropertySpec.Value def = null;
        if (type == PropertySpec.Type.BOOL) {
            if (x.min != null || x.max != null) {
                p.at(x, "7.3", f + (x.min != null ? "/@min" : "/@max"), "a bool property has no range");
                ok = false;
            }
            if (x.defaultValue == null) {
                p.at(x, "7.2", f + "/@default", "required attribute is missing");
                ok = false;
            } else {
                Boolean b = Values.bool(x.defaultValue);
                if (b == null) {
                    p.at(x, "7.2", f + "/@default", "'" + x.defaultValue + "' is not a bool (true or false)");
                    ok = false;
                } else {
                    def = PropertySpec.Value.ofBool(b);
                }
            }
        } else {
            boolean isInt = type == PropertySpec.Type.INT;
            min = bound(p, x, x.min, isInt, f + "/@min");
            max = bound(p, x, x.max, isInt, f + "/@max");
            if ((x.min != null && min.isEmpty()) || (x.max != null && max.isEmpty())) {
                ok = false;
            }
            if (min.isPresent() && max.isPresent() && min.get() > max.get()) {
                p.at(x, "7.3", f + "/@min", "min " + x.min + " is greater than max " + x.max);
                ok = false;
            }
            if (x.defaultValue == null) {
                p.at(x, "7.2", f + "/@default", "required attribute is missing");
                ok = false;
            } else if (isInt) {
                Long v = Values.longValue(x.defaultValue);
                if (v == null || x.defaultValue.trim().startsWith("0x")) {
                    p.at(x, "7.2", f + "/@default", "'" + x.defaultValue + "' is not an int (64-bit decimal integer)");
                    ok = false;
                } else {
                    def = PropertySpec.Value.ofInt(v);
                }
            } else {
                Double v = Values.decimal(x.defaultValue);
                if (v == null) {
                    p.at(x, "7.2", f + "/@default", "'" + x.defaultValue + "' is not a finite decimal number");
                    ok = false;
                } else {
                    def = PropertySpec.Value.ofDouble(v);
                }
            }
            if (def != null) {
                double d = def.asDouble();
                if ((min.isPresent() && d < min.get()) || (max.isPresent() && d > max.get())) {
                    p.at(x, "7.3", f + "/@default", "default " + x.defaultValue + " is outside [" + (x.min == null
                            ? "-inf" : x.min) + ", " + (x.max == null ? "+inf" : x.max) + "]");
                    ok = false;
                }
            }
        }
        String unit = x.unit == null ? "" : x.unit;
        if (!UNIT.matcher(unit).matches()) {
            p.at(x, "7.4", f + "/@unit", "'" + unit + "' is not a unit symbol (up to 16 characters, no spaces)");
            ok = false;
        }
        if (type == PropertySpec.Type.BOOL && !unit.isEmpty()) {
            p.at(x, "7.4", f + "/@unit", "a bool property has no unit");
            ok = false;
        }
        boolean mutable = bool(p, x, x.mutable, false, "7.5", f + "/@mutable");
        if (!ok || def == null) {
            return null;
        }
        return new PropertySpec(x.name, type, def, min, max, unit, mutable, Values.text(x.text));
    }

    private static Optional<Double> bound(Problems p, ContractXml.Prop x, String text, boolean isInt, String f) {
        if (text == null) {
            return Optional.empty();
        }
        if (isInt) {
            Long v = Values.longValue(text);
            if (v == null || text.trim().startsWith("0x")) {
                p.at(x, "7.3", f, "'" + text + "' is not an int");
                return Optional.empty();
            }
            return Optional.of((double) v);
        }
        Double v = Values.decimal(text);
        if (v == null) {
            p.at(x, "7.3", f, "'" + text + "' is not a finite decimal number");
            return Optional.empty();
        }
        return Optional.of(v);
    }

    private static Timing timing(Problems p, ContractXml x, Contract.TaskType task) {
        ContractXml.TimingXml t = x.timing;
        if (t == null) {
            if (task == Contract.TaskType.SERVICE) {
                return new Timing(0, 0, 0, 0, List.of());
            }
            p.at(x, "8", "timing", "required element <timing> is missing (needed by periodic and sporadic tasks)");
            return null;
        }
        boolean ok = true;
        boolean service = task == Contract.TaskType.SERVICE;
        Long period = duration(p, t, t.period, "timing/@period", !service);
        Long wcet = duration(p, t, t.wcet, "timing/@wcet", !service);
        Long deadline = t.deadline == null ? period : duration(p, t, t.deadline, "timing/@deadline", false);
        if ((t.period != null && period == null) || (t.wcet != null && wcet == null)
                || (t.deadline != null && deadline == null) || (!service && (period == null || wcet == null))) {
            ok = false;
        }
        if (period != null && (period <= 0 || period > MAX_PERIOD_NS)) {
            p.at(t, "8.2", "timing/@period", "period " + t.period + " is out of range (0 < period <= 60s)");
            ok = false;
        } else if (wcet != null && wcet <= 0) {
            p.at(t, "8.2", "timing/@wcet", "wcet " + t.wcet + " must be > 0");
            ok = false;
        } else if (deadline != null && deadline <= 0) {
            p.at(t, "8.2", "timing/@deadline", "deadline " + t.deadline + " must be > 0");
            ok = false;
        } else if (period != null && deadline != null && deadline > period) {
            p.at(t, "8.2", "timing/@deadline", "impossible timing: deadline " + t.deadline + " is longer than period "
                    + t.period + " (need 0 < wcet <= deadline <= period)");
            ok = false;
        } else if (wcet != null && deadline != null && wcet > deadline) {
            p.at(t, "8.2", "timing/@wcet", "impossible timing: wcet " + t.wcet + " is longer than deadline "
                    + (t.deadline == null ? t.period : t.deadline) + " (need 0 < wcet <= deadline <= period)");
            ok = false;
        } else if (service && (period == null) != (wcet == null)) {
            p.at(t, "8.5", "timing", "a service task gives both period and wcet, or neither");
            ok = false;
        }
        int priority = 0;
        if (service) {
            if (t.priority != null) {
                p.at(t, "8.5", "timing/@priority", "a service task runs at SCHED_OTHER and has no priority");
                ok = false;
            }
        } else if (t.priority == null) {
            p.at(t, "8.3", "timing/@priority", "required attribute is missing (1..98)");
            ok = false;
        } else {
            Integer pr = Values.integer(t.priority);
            if (pr == null) {
                p.at(t, "8.3", "timing/@priority", "'" + t.priority + "' is not an integer");
                ok = false;
            } else if (pr < 1 || pr > 98) {
                p.at(t, "8.3", "timing/@priority", "priority " + pr + " is out of range 1..98");
                ok = false;
            } else {
                priority = pr;
            }
        }
        List<Integer> cpus = new ArrayList<>();
        if (t.cpus != null && !t.cpus.isBlank()) {
            String c = t.cpus.replace(" ", "");
            if (!CPUS.matcher(c).matches()) {
                p.at(t, "8.4", "timing/@cpus", "'" + t.cpus + "' is not a CPU list (e.g. 1 or 0,2-3)");
                ok = false;
            } else {
                TreeSet<Integer> set = new TreeSet<>();
                for (String part : c.split(",")) {
                    String[] r = part.split("-");
                    int lo = Integer.parseInt(r[0]);
                    int hi = r.length > 1 ? Integer.parseInt(r[1]) : lo;
                    if (lo > hi || hi > MAX_CPU) {
                        p.at(t, "8.4", "timing/@cpus", "'" + part + "' is not a CPU range within 0.." + MAX_CPU);
                        ok = false;
                        break;
                    }
                    for (int i = lo; i <= hi; i++) {
                        if (!set.add(i)) {
                            p.at(t, "8.4", "timing/@cpus", "CPU " + i + " is listed twice");
                            ok = false;
                        }
                    }
                }
                cpus.addAll(set);
            }
        }
        boolean exclusive = false;
        if (t.exclusive != null) {
            Boolean b = Values.bool(t.exclusive);
            if (b == null) {
                p.at(t, "8.6", "timing/@exclusive", "'" + t.exclusive + "' is not a bool (true or false)");
                ok = false;
            } else if (service && b) {
                p.at(t, "8.6", "timing/@exclusive",
                        "a service task runs at SCHED_OTHER on no reserved CPU and cannot hold one exclusively");
                ok = false;
            } else {
                exclusive = b;
            }
        }
        if (!ok) {
            return null;
        }
        return new Timing(period == null ? 0 : period, deadline == null ? 0 : deadline, wcet == null ? 0 : wcet,
                priority, cpus, exclusive);
    }

    private static Long duration(Problems p, Located node, String text, String field, boolean required) {
        if (text == null) {
            if (required) {
                p.at(node, "8.2", field, "required attribute is missing");
            }
            return null;
        }
        Long v = Values.durationNs(text);
        if (v == null) {
            p.at(node, "8.1", field, "'" + text + "' is not a duration (integer with unit ns, us, ms or s, e.g. 50us)");
        }
        return v;
    }

    private static FaultPolicy fault(Problems p, ContractXml x, Timing timing, Contract.TaskType task) {
        ContractXml.Fault f = x.fault;
        if (f == null) {
            p.at(x, "11", "fault", "required element <fault> is missing");
            return null;
        }
        boolean ok = true;
        FaultPolicy.Restart restart = null;
        if (f.restart == null) {
            p.at(f, "11", "fault/@restart", "required attribute is missing (permanent, transient or temporary)");
            ok = false;
        } else {
            switch (f.restart) {
                case "permanent" -> restart = FaultPolicy.Restart.PERMANENT;
                case "transient" -> restart = FaultPolicy.Restart.TRANSIENT;
                case "temporary" -> restart = FaultPolicy.Restart.TEMPORARY;
                default -> {
                    p.at(f, "11", "fault/@restart", "'" + f.restart + "' is not permanent, transient or temporary");
                    ok = false;
                }
            }
        }
        FaultPolicy.SafeOutput safe = null;
        if (f.safe == null) {
            p.at(f, "11", "fault/@safe", "required attribute is missing (hold or zero)");
            ok = false;
        } else if ("hold".equals(f.safe)) {
            safe = FaultPolicy.SafeOutput.HOLD;
        } else if ("zero".equals(f.safe)) {
            safe = FaultPolicy.SafeOutput.ZERO;
        } else {
            p.at(f, "11", "fault/@safe", "'" + f.safe + "' is not hold or zero");
            ok = false;
        }
        int intensity = 3;
        if (f.intensity != null) {
            Integer i = Values.integer(f.intensity);
            if (i == null || i < 0 || i > MAX_INTENSITY) {
                p.at(f, "11", "fault/@intensity", "'" + f.intensity + "' is not an integer 0.." + MAX_INTENSITY);
                ok = false;
            } else {
                intensity = i;
            }
        }
        Long window = millis(p, f, f.window, "fault/@window", 10_000, 1, 3_600_000);
        Long backoff = millis(p, f, f.backoff, "fault/@backoff", 100, 0, 60_000);
        Long heartbeat = millis(p, f, f.heartbeatTimeout, "fault/@heartbeatTimeout", 100, 1, 60_000);
        Long orphanHold = millis(p, f, f.orphanHold, "fault/@orphanHold", FaultPolicy.DEFAULT_ORPHAN_HOLD_MS, 0, 60_000);
        if (window == null || backoff == null || heartbeat == null || orphanHold == null) {
            ok = false;
        }
        if (heartbeat != null && timing != null && task != Contract.TaskType.SERVICE
                && heartbeat * 1_000_000L < timing.periodNs()) {
            p.at(f, "11", "fault/@heartbeatTimeout", "heartbeat timeout " + Values.formatDuration(heartbeat * 1_000_000L)
                    + " is shorter than the period " + Values.formatDuration(timing.periodNs()));
            ok = false;
        }
        return ok ? new FaultPolicy(restart, intensity, window, backoff, safe, heartbeat, orphanHold) : null;
    }

    private static Long millis(Problems p, Located node, String text, String field, long dflt, long min, long max) {
        if (text == null) {
            return dflt;
        }
        Long ns = Values.durationNs(text);
        if (ns == null) {
            p.at(node, "8.1", field, "'" + text + "' is not a duration (integer with unit ns, us, ms or s, e.g. 100ms)");
            return null;
        }
        if (ns % 1_000_000L != 0) {
            p.at(node, "11", field, "'" + text + "' is not a whole number of milliseconds");
            return null;
        }
        long ms = ns / 1_000_000L;
        if (ms < min || ms > max) {
            p.at(node, "11", field, "'" + text + "' is out of range " + Values.formatDuration(min * 1_000_000L) + ".."
                    + Values.formatDuration(max * 1_000_000L));
            return null;
        }
        return ms;
    }

    private static Optional<UpdateSpec> update(Problems p, ContractXml.Update u) {
        boolean ok = true;
        URI uri = null;
        if (u.url == null) {
            p.at(u, "12", "update/@url", "required attribute is missing");
            ok = false;
        } else {
            try {
                uri = new URI(u.url);
                String scheme = uri.getScheme() == null ? "" : uri.getScheme().toLowerCase(Locale.ROOT);
                if (!scheme.equals("https") && !scheme.equals("file")) {
                    p.at(u, "12", "update/@url", "scheme '" + (uri.getScheme() == null ? "" : uri.getScheme())
                            + "' is not allowed; only https and file URLs");
                    ok = false;
                } else if (scheme.equals("https") && (uri.getHost() == null || uri.getHost().isEmpty())) {
                    p.at(u, "12", "update/@url", "an https URL needs a host");
                    ok = false;
                } else if (scheme.equals("file") && (uri.getPath() == null || !uri.getPath().startsWith("/"))) {
                    p.at(u, "12", "update/@url", "a file URL needs an absolute path (file:/path/x.jar)");
                    ok = false;
                } else if (uri.getUserInfo() != null) {
                    p.at(u, "12", "update/@url", "credentials in the URL are not allowed");
                    ok = false;
                }
            } catch (URISyntaxException e) {
                p.at(u, "12", "update/@url", "'" + u.url + "' is not a URL: " + e.getReason());
                ok = false;
            }
        }
        if (u.sha256 == null) {
            p.at(u, "12", "update/@sha256", "required attribute is missing (64 hex digits)");
            ok = false;
        } else if (!SHA256.matcher(u.sha256).matches()) {
            p.at(u, "12", "update/@sha256", "'" + u.sha256 + "' is not a SHA-256 (exactly 64 hex digits)");
            ok = false;
        }
        return ok ? Optional.of(new UpdateSpec(uri, u.sha256.toLowerCase(Locale.ROOT))) : Optional.empty();
    }

    private static boolean bool(Problems p, Located node, String text, boolean dflt, String section, String field) {
        if (text == null) {
            return dflt;
        }
        Boolean b = Values.bool(text);
        if (b == null) {
            p.at(node, section, field, "'" + text + "' is not a bool (true or false)");
            return dflt;
        }
        return b;
    }
}
