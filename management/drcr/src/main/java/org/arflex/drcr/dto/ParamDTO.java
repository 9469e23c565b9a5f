package org.arflex.drcr.dto;

/** A parameter and the value the RT half applied. */
public class ParamDTO {
    /** Parameter name. */
    public String name;
    /** BOOL, INT or DOUBLE. */
    public String type;
    /** The value last applied by the RT half (or the configured value when none runs). */
    public String value;
    /** Default value. */
    public String defaultValue;
    /** Inclusive lower bound, or null. */
    public Double min;
    /** Inclusive upper bound, or null. */
    public Double max;
    /** Unit text. */
    public String unit;
    /** May change while Active. */
    public boolean mutable;
}
