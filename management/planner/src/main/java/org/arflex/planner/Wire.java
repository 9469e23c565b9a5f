package org.arflex.planner;

import java.util.Objects;

/**
 * One resolved connection: input {@code inPort} of {@code consumer} reads output
 * {@code outPort} of {@code provider}. Wires are ordered by consumer, input, provider, output.
 *
 * @param consumer component that owns the input
 * @param inPort   input port name
 * @param provider component that owns the output (may equal {@code consumer} for an explicit
 *                 self-binding)
 * @param outPort  output port name
 */
public record Wire(String consumer, String inPort, String provider, String outPort) implements Comparable<Wire> {

    public Wire {
        Objects.requireNonNull(consumer, "consumer");
        Objects.requireNonNull(inPort, "inPort");
        Objects.requireNonNull(provider, "provider");
        Objects.requireNonNull(outPort, "outPort");
    }

    /** {@code provider.outPort}, as written in binding rules and messages. */
    public String source() {
        return provider + "." + outPort;
    }

    /** {@code consumer.inPort}. */
    public String target() {
        return consumer + "." + inPort;
    }

    @Override
    public int compareTo(Wire o) {
        // By consumer, input, provider, output (plans compare every wire of the cell).
        int c = consumer.compareTo(o.consumer);
        if (c == 0) {
            c = inPort.compareTo(o.inPort);
        }
        if (c == 0) {
            c = provider.compareTo(o.provider);
        }
        return c != 0 ? c : outPort.compareTo(o.outPort);
    }

    /** {@code consumer.inPort <- provider.outPort}. */
    @Override
    public String toString() {
        return target() + " <- " + source();
    }
}
