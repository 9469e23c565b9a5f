package org.arflex.contract;

import java.util.ArrayList;
import java.util.List;
import java.util.Locale;
import java.util.Map;
import java.util.Objects;
import java.util.regex.Pattern;

/**
 * An LDAP-style filter over provider attributes, in the string syntax of RFC 1960 (as OSGi
 * filters), used by input bindings (spec §6.6). Examples: {@code (role=robot)},
 * {@code (&(role=camera)(!(sim=true)))}, {@code (name=cam*)}, {@code (rate>=100)}, {@code (vendor=*)}.
 *
 * <p>Matching rules: attribute names are compared case-insensitively; {@code =} compares text
 * exactly ({@code *} in the value makes it a substring match; {@code =*} tests presence);
 * {@code ~=} compares ignoring case and white space; {@code >=} and {@code <=} compare as
 * numbers when both sides are decimal numbers, otherwise as text. A backslash escapes the next
 * character of a value; {@code (}, {@code )}, {@code *} and {@code \} must be escaped to be
 * literal. Instances are immutable.
 */
public final class Filter {
    /** Longest filter text accepted. */
    public static final int MAX_LENGTH = 4096;
    /** Deepest nesting accepted. */
    public static final int MAX_DEPTH = 32;

    private static final Pattern NUMBER = Pattern.compile("[+-]?([0-9]+(\\.[0-9]*)?|\\.[0-9]+)([eE][+-]?[0-9]+)?");

    private final Node root;
    private final String text;

    private Filter(Node root) {
        this.root = root;
        StringBuilder b = new StringBuilder();
        root.write(b);
        this.text = b.toString();
    }

    /** Parses a filter; throws {@link SyntaxException} naming the offset and what was expected. */
    public static Filter parse(String text) {
        Objects.requireNonNull(text, "filter");
        if (text.length() > MAX_LENGTH) {
            throw new SyntaxException("filter is longer than " + MAX_LENGTH + " characters", MAX_LENGTH);
        }
        Parser p = new Parser(text);
        p.skipSpace();
        Node n = p.filter(0);
        p.skipSpace();
        if (p.pos != text.length()) {
            throw new SyntaxException("unexpected '" + text.charAt(p.pos) + "' after the filter", p.pos);
        }
        return new Filter(n);
    }

    /** True when the attributes satisfy the filter. */
    public boolean matches(Map<String, String> attributes) {
        Map<String, String> lower = new java.util.HashMap<>();
        attributes.forEach((k, v) -> lower.putIfAbsent(k.toLowerCase(Locale.ROOT), v));
        return root.eval(lower);
    }

    /** The canonical text of the filter (values re-escaped). */
    @Override
    public String toString() {
        return text;
    }

    @Override
    public boolean equals(Object o) {
        return o instanceof Filter f && f.text.equals(text);
    }

    @Override
    public int hashCode() {
        return text.hashCode();
    }

    /** A filter syntax error, with the offset (0-based) where it was found. */
    public static final class SyntaxException extends IllegalArgumentException {
        private static final long serialVersionUID = 1L;
        private final int position;

        SyntaxException(String message, int position) {
            super(message + " (at offset " + position + ")");
            this.position = position;
        }

        /** 0-based offset into the filter text. */
        public int position() {
            return position;
        }
    }

    private interface Node {
        boolean eval(Map<String, String> attrs);

        void write(StringBuilder b);
    }

    private record And(List<Node> parts) implements Node {
        public boolean eval(Map<String, String> a) {
            return parts.stream().allMatch(n -> n.eval(a));
        }

        public void write(StringBuilder b) {
            b.append("(&");
            parts.forEach(n -> n.write(b));
            b.append(')');
        }
    }

    private record Or(List<Node> parts) implements Node {
        public boolean eval(Map<String, String> a) {
            return parts.stream().anyMatch(n -> n.eval(a));
        }

        public void write(StringBuilder b) {
            b.append("(|");
            parts.forEach(n -> n.write(b));
            b.append(')');
        }
    }

    private record Not(Node inner) implements Node {
        public boolean eval(Map<String, String> a) {
            return !inner.eval(a);
        }

        public void write(StringBuilder b) {
            b.append("(!");
            inner.write(b);
            b.append(')');
        }
    }

    private enum Op {
        EQ("="), APPROX("~="), GE(">="), LE("<=");

        final String text;

        Op(String text) {
            this.text = text;
        }
    }

    private record Compare(String attr, Op op, String value) implements Node {
        public boolean eval(Map<String, String> a) {
            String v = a.get(attr.toLowerCase(Locale.ROOT));
            if (v == null) {
                return false;
            }
            return switch (op) {
                case EQ -> v.equals(value);
                case APPROX -> squash(v).equals(squash(value));
                case GE -> compare(v, value) >= 0;
                case LE -> compare(v, value) <= 0;
            };
        }

        public void write(StringBuilder b) {
            b.append('(').append(attr).append(op.text);
            escape(value, b);
            b.append(')');
        }
    }

    private record Present(String attr) implements Node {
        public boolean eval(Map<String, String> a) {
            return a.containsKey(attr.toLowerCase(Locale.ROOT));
        }

        public void write(StringBuilder b) {
            b.append('(').append(attr).append("=*)");
        }
    }

    /** {@code pieces} are the literal texts between stars; first and last may be empty. */
    private record Substring(String attr, List<String> pieces) implements Node {
        public boolean eval(Map<String, String> a) {
            String v = a.get(attr.toLowerCase(Locale.ROOT));
            if (v == null) {
                return false;
            }
            String first = pieces.get(0);
            String last = pieces.get(pieces.size() - 1);
            if (!v.startsWith(first)) {
                return false;
            }
            int at = first.length();
            for (int i = 1; i < pieces.size() - 1; i++) {
                int k = v.indexOf(pieces.get(i), at);
                if (k < 0) {
                    return false;
                }
                at = k + pieces.get(i).length();
            }
            return v.length() - at >= last.length() && v.endsWith(last);
        }

        public void write(StringBuilder b) {
            b.append('(').append(attr).append('=');
            for (int i = 0; i < pieces.size(); i++) {
                if (i > 0) {
                    b.append('*');
                }
                escape(pieces.get(i), b);
            }
            b.append(')');
        }
    }

    private static String squash(String s) {
        StringBuilder b = new StringBuilder();
        for (int i = 0; i < s.length(); i++) {
            char c = s.charAt(i);
            if (!Character.isWhitespace(c)) {
                b.append(Character.toLowerCase(c));
            }
        }
        return b.toString();
    }

    private static int compare(String a, String b) {
        if (NUMBER.matcher(a.trim()).matches() && NUMBER.matcher(b.trim()).matches()) {
            return Double.compare(Double.parseDouble(a.trim()), Double.parseDouble(b.trim()));
        }
        return a.compareTo(b);
    }

    private static void escape(String s, StringBuilder b) {
        for (int i = 0; i < s.length(); i++) {
            char c = s.charAt(i);
            if (c == '(' || c == ')' || c == '*' || c == '\\') {
                b.append('\\');
            }
            b.append(c);
        }
    }

    private static final class Parser {
        final String s;
        int pos;

        Parser(String s) {
            this.s = s;
        }

        void skipSpace() {
            while (pos < s.length() && Character.isWhitespace(s.charAt(pos))) {
                pos++;
            }
        }

        SyntaxException error(String what) {
            return new SyntaxException(what, pos);
        }

        void expect(char c) {
            if (pos >= s.length()) {
                throw error("expected '" + c + "' but the filter ended");
            }
            if (s.charAt(pos) != c) {
                throw error("expected '" + c + "' but found '" + s.charAt(pos) + "'");
            }
            pos++;
        }

        Node filter(int depth) {
            if (depth >= MAX_DEPTH) {
                throw error("filter nests deeper than " + MAX_DEPTH);
            }
            expect('(');
            skipSpace();
            if (pos >= s.length()) {
                throw error("filter ended inside '('");
            }
            Node n;
            char c = s.charAt(pos);
            if (c == '&' || c == '|') {
                pos++;
                List<Node> parts = new ArrayList<>();
                skipSpace();
                while (pos < s.length() && s.charAt(pos) == '(') {
                    parts.add(filter(depth + 1));
                    skipSpace();
                }
                if (parts.isEmpty()) {
                    throw error("'" + c + "' needs at least one operand filter");
                }
                n = c == '&' ? new And(List.copyOf(parts)) : new Or(List.copyOf(parts));
            } else if (c == '!') {
                pos++;
                skipSpace();
                n = new Not(filter(depth + 1));
                skipSpace();
            } else {
                n = item();
            }
            expect(')');
            return n;
        }

        Node item() {
            int start = pos;
            while (pos < s.length() && "=<>~()*\\".indexOf(s.charAt(pos)) < 0) {
                pos++;
            }
            String attr = s.substring(start, pos).trim();
            if (attr.isEmpty()) {
                throw error("expected an attribute name");
            }
            if (pos >= s.length()) {
                throw error("expected an operator (=, ~=, >=, <=) after '" + attr + "'");
            }
            Op op;
            char c = s.charAt(pos);
            if (c == '=') {
                op = Op.EQ;
                pos++;
            } else if ((c == '~' || c == '>' || c == '<') && pos + 1 < s.length() && s.charAt(pos + 1) == '=') {
                op = c == '~' ? Op.APPROX : c == '>' ? Op.GE : Op.LE;
                pos += 2;
            } else {
                throw error("expected an operator (=, ~=, >=, <=) after '" + attr + "'");
            }
            List<String> pieces = new ArrayList<>();
            StringBuilder cur = new StringBuilder();
            while (true) {
                if (pos >= s.length()) {
                    throw error("value of '" + attr + "' is not closed by ')'");
                }
                char v = s.charAt(pos);
                if (v == ')') {
                    break;
                }
                if (v == '(') {
                    throw error("'(' in a value must be escaped as \\(");
                }
                if (v == '\\') {
                    if (pos + 1 >= s.length()) {
                        throw error("dangling backslash at the end of a value");
                    }
                    cur.append(s.charAt(pos + 1));
                    pos += 2;
                    continue;
                }
                if (v == '*') {
                    pieces.add(cur.toString());
                    cur.setLength(0);
                    pos++;
                    continue;
                }
                cur.append(v);
                pos++;
            }
            pieces.add(cur.toString());
            if (pieces.size() == 1) {
                return new Compare(attr, op, pieces.get(0));
            }
            if (op != Op.EQ) {
                throw error("'*' wildcards are only allowed with '='");
            }
            if (pieces.size() == 2 && pieces.get(0).isEmpty() && pieces.get(1).isEmpty()) {
                return new Present(attr);
            }
            return new Substring(attr, List.copyOf(pieces));
        }
    }
}
