package org.arflex.contract;

import java.util.ArrayList;
import java.util.HashSet;
import java.util.List;
import java.util.Map;
import java.util.Optional;
import java.util.Set;
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
    private final PortValidation portValidation;

    ContractValidator(PortTypes types) {
        this.types = types;
        this.stateValidation = new StateValidation(types);
        this.rolloutValidation = new RolloutValidation(types);
        this.portValidation = new PortValidation(types);
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
        Map<String, String> attributes = AttributeValidation.check(p, x);

        // §6 ports
        List<PortSpec> ports = new ArrayList<>();
        if (x.ports != null) {
            Set<String> seen = new HashSet<>();
            for (ContractXml.Port port : x.ports.list) {
                PortSpec ps = portValidation.check(p, port, seen);
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
                PropertySpec ps = PropertyValidation.check(p, prop, seen);
                if (ps != null) {
                    properties.add(ps);
                }
            }
        }

        // §8 timing
        Timing timing = TimingValidation.check(p, x, task);

        // §9 resources
        Resources resources = ResourceValidation.check(p, x);

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
        FaultPolicy fault = FaultValidation.check(p, x, timing, task);

        // §12 update
        Optional<UpdateSpec> update = Optional.empty();
        if (x.update != null) {
            update = UpdateValidation.check(p, x.update);
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

    static boolean bool(Problems p, Located node, String text, boolean dflt, String section, String field) {
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
