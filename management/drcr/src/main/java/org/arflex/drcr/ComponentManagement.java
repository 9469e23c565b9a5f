package org.arflex.drcr;

import org.arflex.drcr.dto.InstanceDTO;
import org.arflex.drcr.dto.StatsDTO;

/**
 * Management of one component instance, registered once per instance with the service
 * property {@code arflex.component=<name>}.
 */
public interface ComponentManagement {

    /** Service property naming the instance. */
    String COMPONENT_PROPERTY = "arflex.component";

    /** The instance name. */
    String name();

    /** A snapshot of the instance (state, target state, bindings, parameters, statistics). */
    InstanceDTO instance();

    /** Current lifecycle state name. */
    String state();

    /**
     * The value of a parameter as the RT half applied it (as configured when no RT half runs).
     *
     * @throws IllegalArgumentException naming the parameter when it does not exist
     */
    String get(String param);

    /**
     * Sets a parameter: checks type, range and mutability, sends it to the RT half and waits
     * until the RT half applied it.
     *
     * @return the applied value read back from the control block
     * @throws IllegalArgumentException naming the parameter and the rule broken
     * @throws IllegalStateException when the RT half did not apply it in time
     */
    String set(String param, String value);

    /** RT statistics, or null when no RT half runs. */
    StatsDTO stats();

    /**
     * Operator reset: lets a component that moves hardware drive its outputs again after a
     * restart, and gives a Failed instance a new chance.
     */
    void reset();
}
