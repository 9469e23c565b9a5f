package org.arflex.contract;

import java.util.List;
import java.util.Map;
import java.util.Optional;

/**
 * A validated, immutable component contract (spec: contracts/SPEC.md). Instances are only
 * produced by {@link ContractParser}; every list and map is unmodifiable.
 *
 * @param name         component name, unique in a runtime ({@code [a-z][a-z0-9-]{0,47}})
 * @param version      semantic version of the component
 * @param description  free text, may be empty
 * @param executable   name of the RT executable inside the bundle ({@code native/linux-x86_64/<executable>})
 * @param taskType     how the RT half is scheduled
 * @param movesHardware true when the component commands motion: after a restart it waits for an
 *                     operator reset before it drives outputs again
 * @param attributes   provider attributes that input binding filters match against
 * @param ports        inputs and outputs in declaration order
 * @param properties   typed parameters in declaration order
 * @param timing       period, deadline, WCET, priority, CPU set
 * @param resources    memory and network budget
 * @param criticality  larger is more critical; the lowest goes first when resources shrink
 * @param fault        restart and safe-output policy
 * @param update       where updates come from, if anywhere
 * @param source       where this contract was read from, for error messages
 * @param state        the state block it hands to its next version at a change set's switch, if any
 *                     (SPEC §12.1)
 * @param rollout      how a new version is shadowed, compared and switched in a change set (SPEC §12.2)
 * @param motionThroughOutputs true when a component that moves hardware commands its motion only
 *                     through its output ports, to a component that drives the device
 *                     ({@code implementation/@motionThrough="outputs"}, SPEC §4.3); false (the
 *                     default) when its RT half drives a device itself, so two of its halves must
 *                     never run side by side
 */
public record Contract(
        String name,
        String version,
        String description,
        String executable,
        TaskType taskType,
        boolean movesHardware,
        Map<String, String> attributes,
        List<PortSpec> ports,
        List<PropertySpec> properties,
        Timing timing,
        Resources resources,
        int criticality,
        FaultPolicy fault,
        Optional<UpdateSpec> update,
        String source,
        Optional<StateSpec> state,
        Optional<RolloutSpec> rollout,
        boolean motionThroughOutputs) {

    public Contract {
        attributes = Map.copyOf(attributes);
        state = state == null ? Optional.empty() : state;
        rollout = rollout == null ? Optional.empty() : rollout;
        ports = List.copyOf(ports);
        properties = List.copyOf(properties);
    }

    /** A contract whose motion, if it moves hardware, goes to a device of its own (SPEC §4.3). */
    public Contract(String name, String version, String description, String executable, TaskType taskType,
                    boolean movesHardware, Map<String, String> attributes, List<PortSpec> ports,
                    List<PropertySpec> properties, Timing timing, Resources resources, int criticality,
                    FaultPolicy fault, Optional<UpdateSpec> update, String source, Optional<StateSpec> state,
                    Optional<RolloutSpec> rollout) {
        this(name, version, description, executable, taskType, movesHardware, attributes, ports, properties, timing,
                resources, criticality, fault, update, source, state, rollout, false);
    }

    /** A contract without a state block (SPEC §12.1) and without a {@code <rollout>} (SPEC §12.2). */
    public Contract(String name, String version, String description, String executable, TaskType taskType,
                    boolean movesHardware, Map<String, String> attributes, List<PortSpec> ports,
                    List<PropertySpec> properties, Timing timing, Resources resources, int criticality,
                    FaultPolicy fault, Optional<UpdateSpec> update, String source) {
        this(name, version, description, executable, taskType, movesHardware, attributes, ports, properties, timing,
                resources, criticality, fault, update, source, Optional.empty(), Optional.empty(), false);
    }

    /** The inputs, in declaration order. */
    public List<PortSpec> inputs() {
        return ports.stream().filter(p -> p.direction() == PortSpec.Direction.IN).toList();
    }

    /** The outputs, in declaration order. */
    public List<PortSpec> outputs() {
        return ports.stream().filter(p -> p.direction() == PortSpec.Direction.OUT).toList();
    }

    /** The port of that name, if declared. */
    public Optional<PortSpec> port(String portName) {
        return ports.stream().filter(p -> p.name().equals(portName)).findFirst();
    }

    /** The property of that name, if declared. */
    public Optional<PropertySpec> property(String propertyName) {
        return properties.stream().filter(p -> p.name().equals(propertyName)).findFirst();
    }

    /** How the RT half is scheduled. */
    public enum TaskType {
        /** A periodic loop at {@link Timing#periodNs()}. */
        PERIODIC,
        /** Released by input events, at most once per {@link Timing#periodNs()} (minimum inter-arrival). */
        SPORADIC,
        /** Not real-time: no admission test on CPU, runs at SCHED_OTHER. */
        SERVICE
    }
}
