package org.arflex.drcr;

import org.arflex.drcr.dto.InstanceDTO;
import org.arflex.drcr.dto.PortValueDTO;
import org.arflex.drcr.dto.StatsDTO;

/**
 * Management of one component instance, registered once per instance with the service
 * property {@code arflex.component=<name>}.
 */
public interface ComponentManagement {

    /** Service property naming the instance. */
    String COMPONENT_PROPERTY = "arflex.component";

    /**
     * Since 0.5.0: service property holding the instance's lifecycle state (INSTALLED,
     * UNSATISFIED, ACTIVE, DESTROYED or FAILED, as {@link #state()}), changed with the state
     * (a {@code MODIFIED} service event). Readiness is this service: a client waits for a
     * component by tracking {@code (&(arflex.component=vision)(arflex.state=ACTIVE))}, e.g. with a
     * {@code ServiceTracker}, as the shell's {@code arflex:await} waits for the same state.
     */
    String STATE_PROPERTY = "arflex.state";

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
     * Since 0.2.0: the newest value of one of this instance's output ports, read from a
     * read-only mapping of the port segment under the slot's seqlock (the producer is never
     * written to, locked or slowed) and decoded with the port type's field definitions. For a
     * stream or frame port the newest slot is copied, nothing is consumed. Runs off the DRCR's
     * actor thread except for a short lookup of the segment. Callers should poll at a modest
     * rate (the web console: at most 10 Hz per port).
     *
     * @return the value; {@link PortValueDTO#index} is -1 when nothing was published yet
     * @throws IllegalArgumentException naming the port when this instance has no such output
     * @throws IllegalStateException when the segment cannot be read (gone, wrong type)
     */
    PortValueDTO portValue(String port);

    /**
     * Operator reset: lets a component that moves hardware drive its outputs again after a
     * restart, and gives a Failed instance a new chance.
     */
    void reset();
}
