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
}
