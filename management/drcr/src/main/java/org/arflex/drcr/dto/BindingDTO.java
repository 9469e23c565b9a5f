package org.arflex.drcr.dto;

/** A wire from a provider's output to a consumer's input. */
public class BindingDTO {
    /** Consumer instance. */
    public String consumer;
    /** Consumer input port. */
    public String input;
    /** Provider instance. */
    public String provider;
    /** Provider output port. */
    public String output;
    /**
     * Values the consumer refused on this input in its current run: a damaged segment, or
     * values its validator rejected (NaN, Inf, out of range). Since 0.8.0.
     */
    public long rejected;
}
