package org.arflex.planner;

import java.util.Comparator;
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

    private static final Comparator<Wire> ORDER = Comparator.comparing(Wire::consumer)
            .thenComparing(Wire::inPort).thenComparing(Wire::provider).thenComparing(Wire::outPort);

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
        return ORDER.compare(this, o);
    }

    /** {@code consumer.inPort <- provider.outPort}. */
    @Override
    public String toString() {
        return target() + " <- " + source();
    }
}
