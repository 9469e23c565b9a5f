package org.arflex.contract;

/**
 * One problem found in a contract (or a port type definition): where it is, which spec section
 * it breaks, which field, and what is wrong. Lines and columns are 1-based; 0 when unknown.
 *
 * @param source  file name (or other label) of the document
 * @param line    1-based line of the element holding the field, 0 if unknown
 * @param column  1-based column of that element, 0 if unknown
 * @param section the contracts/SPEC.md section the rule comes from, for example {@code "6.3"}
 * @param field   the field, as an XML path, for example {@code ports/out[y]/@depth}
 * @param message what is wrong, in plain words
 */
public record Problem(String source, int line, int column, String section, String field, String message) {

    /** {@code source:line:column: [§section] field: message}. */
    @Override
    public String toString() {
        return source + ":" + line + ":" + column + ": [§" + section + "] " + field + ": " + message;
    }
}
