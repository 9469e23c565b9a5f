package org.arflex.contract.internal;

/** The text of a simple element, with its location. */
public final class Text extends Located {
    /** The element's text, never null (empty for an empty element). */
    public String value = "";
    /** True when the element had attributes or children (then it is not simple text). */
    public boolean structured;
}
