package org.arflex.contract.internal;

/** A binding-model node that knows where its element starts (set by {@link Binder}). */
public abstract class Located {
    /** 1-based line of the element's start tag, 0 if unknown. */
    public int line;
    /** 1-based column of the element's start tag, 0 if unknown. */
    public int column;
    /** Names of child elements that appeared more than once where one is allowed. */
    public final java.util.List<String> duplicates = new java.util.ArrayList<>();

    void at(int line, int column) {
        this.line = line;
        this.column = column;
    }

    /** Records {@code name} as duplicated when {@code previous} was already set. */
    protected void once(Object previous, String name) {
        if (previous != null) {
            duplicates.add(name);
        }
    }
}
