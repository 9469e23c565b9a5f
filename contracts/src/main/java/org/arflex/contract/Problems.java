package org.arflex.contract;

import java.util.List;
import org.arflex.contract.internal.Located;

/** The one factory of validation problems: prefixes the file and the element's line and column. */
final class Problems {
    private final String source;
    private final List<Problem> out;
    private final int start;

    Problems(String source, List<Problem> out) {
        this.source = source;
        this.out = out;
        this.start = out.size();
    }

    /** A problem located at {@code node}'s start tag (or 0:0 when node is null). */
    void at(Located node, String section, String field, String message) {
        out.add(new Problem(source, node == null ? 0 : node.line, node == null ? 0 : node.column, section, field,
                message));
    }

    /** True when no problem was added through this factory's list since it was made. */
    boolean clean() {
        return out.size() == start;
    }
}
