package org.arflex.contract.internal;

import com.fasterxml.jackson.core.JsonLocation;
import com.fasterxml.jackson.core.JsonProcessingException;
import java.util.IdentityHashMap;
import java.util.Map;
import javax.xml.stream.Location;
import javax.xml.stream.XMLStreamException;
import org.arflex.contract.Problem;

/**
 * Turns whatever the XML stack throws (Woodstox's checked {@link XMLStreamException}, its
 * unchecked {@code WstxLazyException} for errors found while text is read lazily, Jackson's
 * {@link JsonProcessingException} subtypes wrapping either, an {@link IllegalArgumentException}
 * from a limit) into one §2.1 {@link Problem}, located where the parser knows.
 *
 * <p>Decisions: the location is the first one found along the cause chain (Woodstox's own,
 * which is the most precise, is usually the innermost; Jackson's is the token's); when none
 * has one, the reader's current position is used. The message is that of the innermost XML
 * exception, without the wrapper's class name or location prefix.
 */
public final class XmlFailure {
    /** Causes followed at most (guards against pathological chains). */
    private static final int MAX_CAUSES = 16;

    private XmlFailure() {
    }

    /**
     * The problem for {@code e}, at the parser's location, else at {@code fallback} (may be
     * null), else at 0:0.
     */
    public static Problem problem(Throwable e, String source, Location fallback) {
        int line = 0;
        int column = 0;
        Throwable message = e;
        Map<Throwable, Boolean> seen = new IdentityHashMap<>();
        for (Throwable t = e; t != null && seen.size() < MAX_CAUSES && seen.put(t, Boolean.TRUE) == null;
                t = t.getCause()) {
            if (t instanceof XMLStreamException x) {
                message = x;
                Location l = x.getLocation();
                if (line <= 0 && l != null && l.getLineNumber() > 0) {
                    line = l.getLineNumber();
                    column = Math.max(l.getColumnNumber(), 0);
                }
            } else if (t instanceof JsonProcessingException j) {
                JsonLocation l = j.getLocation();
                if (line <= 0 && l != null && l.getLineNr() > 0) {
                    line = l.getLineNr();
                    column = Math.max(l.getColumnNr(), 0);
                }
            }
        }
        if (line <= 0 && fallback != null && fallback.getLineNumber() > 0) {
            line = fallback.getLineNumber();
            column = Math.max(fallback.getColumnNumber(), 0);
        }
        if (line > 0) {
            // Woodstox counts columns from 0 at the start of a line (an empty document fails at
            // 1:0); a Problem's columns are 1-based
            column = Math.max(column, 1);
        }
        String text = message instanceof JsonProcessingException j && j.getOriginalMessage() != null
                ? SecureXml.describe(j.getOriginalMessage())
                : SecureXml.describe(message.getMessage() == null ? message.getClass().getSimpleName()
                        : message.getMessage());
        return new Problem(source, Math.max(line, 0), column, "2.1", "(document)", text);
    }

    /** True when {@code e} or one of its causes is a parser (not a data binding) failure. */
    public static boolean fromParser(Throwable e) {
        Map<Throwable, Boolean> seen = new IdentityHashMap<>();
        for (Throwable t = e; t != null && seen.size() < MAX_CAUSES && seen.put(t, Boolean.TRUE) == null;
                t = t.getCause()) {
            if (t instanceof XMLStreamException || t.getClass().getName().startsWith("com.ctc.wstx.")) {
                return true;
            }
        }
        return false;
    }
}
