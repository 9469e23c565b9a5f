package org.arflex.contract;

import java.util.Optional;

/**
 * One input or output port of a contract.
 *
 * @param name        port name, unique within its contract
 * @param direction   in or out
 * @param type        port type name, defined in contracts/types (for example {@code arflex.JointState})
 * @param typeVersion version of the port type the component was built against
 * @param method      how values are carried
 * @param depth       ring depth for stream and frame ports (slots); 1 for state ports
 * @param overflow    what a full stream does; ignored for state and frame ports
 * @param binding     for inputs: how a provider is chosen; empty for outputs
 * @param optional    for inputs: the component may be Active without a provider
 * @param safety      for inputs: a safety input (SPEC §6.8): it permits motion; the component
 *                    starts without a provider and holds in a protective stop while it has
 *                    none, and losing its provider is planned as {@code HOLD}, not a rewiring
 */
public record PortSpec(
        String name,
        Direction direction,
        String type,
        TypeVersion typeVersion,
        Method method,
        int depth,
        Overflow overflow,
        Optional<Binding> binding,
        boolean optional,
        boolean safety) {

    /** A port that is not a safety input. */
    public PortSpec(String name, Direction direction, String type, TypeVersion typeVersion, Method method, int depth,
                    Overflow overflow, Optional<Binding> binding, boolean optional) {
        this(name, direction, type, typeVersion, method, depth, overflow, binding, optional, false);
    }

    /** Port direction. */
    public enum Direction { IN, OUT }

    /** Transport method of a port. */
    public enum Method {
        /** Latest value, single writer, many readers (seqlock). */
        STATE,
        /** Bounded single-producer ring; overflow policy decides what is dropped. */
        STREAM,
        /** Ring of large slots (camera images), read without copy. */
        FRAME
    }

    /** What a full stream port drops. */
    public enum Overflow { DROP_OLDEST, DROP_NEWEST }
}
