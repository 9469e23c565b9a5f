package org.arflex.drcr.dto;

/** One port of a contract. */
public class PortDTO {
    /** Port name. */
    public String name;
    /** IN or OUT. */
    public String direction;
    /** Port type name. */
    public String type;
    /** Port type version MAJOR.MINOR. */
    public String typeVersion;
    /** STATE, STREAM or FRAME. */
    public String method;
    /** For inputs: the binding rule as text, or null for any compatible provider. */
    public String binding;
    /** For inputs: may be unbound while Active. */
    public boolean optional;
}
