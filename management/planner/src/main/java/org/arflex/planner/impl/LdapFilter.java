package org.arflex.planner.impl;

import java.util.ArrayList;
import java.util.List;
import java.util.Locale;
import java.util.Map;

/**
 * A small RFC 1960 filter over string attributes, as OSGi filters: {@code (&...)},
 * {@code (|...)}, {@code (!...)}, {@code (a=v)}, {@code (a=*)} (presence), {@code (a=x*y*)}
 * (substrings), {@code (a~=v)} (case and white space insensitive), {@code (a>=v)},
 * {@code (a<=v)} (numeric when both sides are numbers, text otherwise). Attribute names are
 * case-insensitive; {@code \} escapes the next character in values.
 *
 * <p>Kept private to the planner so that it does not depend on the contracts module's own
 * filter, which validates filters when contracts are parsed; both implement the same syntax.
 */
public final class LdapFilter {

    private final Node root;
    private final String text;

    private LdapFilter(Node root, String text) {
        this.root = root;
        this.text = text;
    }

    /**
     * Parses a filter.
     *
     * @throws IllegalArgumentException saying what is wrong and at which character
     */
    public static LdapFilter parse(String text) {
        if (text == null || text.isBlank()) {
            throw new IllegalArgumentException("empty filter");
        }
        Parser p = new Parser(text.trim());
        Node n = p.filter(0);
        if (p.pos != p.s.length()) {
            throw p.error("unexpected text after the filter");
        }
        LdapFilter f = new LdapFilter(n, text);
        f.hint = p.hint;
        return f;
    }

    /** True when the attributes match. */
    public boolean matches(Map<String, String> attributes) {
        return root.eval(attributes);
    }

    @Override
    public String toString() {
        return text;
    }

    private interface Node {
        boolean eval(Map<String, String> a);
    }

    private static String lookup(Map<String, String> a, String key) {
        String v = a.get(key);
        if (v != null) {
            return v;
        }
        for (Map.Entry<String, String> e : a.entrySet()) {
            if (e.getKey().equalsIgnoreCase(key)) {
                return e.getValue();
            }
        }
        return null;
    }

    /** True when the text is a plain decimal number (checked before parsing: no exceptions on the hot path). */
    static boolean numeric(String s) {
        String t = s.trim();
        if (t.isEmpty() || t.length() > 40) {
            return false;
        }
        boolean digit = false;
        for (int i = 0; i < t.length(); i++) {
            char c = t.charAt(i);
            if (c >= '0' && c <= '9') {
                digit = true;
            } else if (!(c == '.' || c == 'e' || c == 'E' || ((c == '-' || c == '+') && (i == 0
                    || t.charAt(i - 1) == 'e' || t.charAt(i - 1) == 'E')))) {
                return false;
            }
        }
        if (!digit) {
            return false;
        }
        try {
            Double.parseDouble(t);
            return true;
        } catch (NumberFormatException e) {
            return false;
        }
    }

    private static int compare(String actual, String wanted) {
        if (numeric(actual) && numeric(wanted)) {
            return Double.compare(Double.parseDouble(actual.trim()), Double.parseDouble(wanted.trim()));
        }
        return actual.compareTo(wanted);
    }

    /** {@code =} compares text exactly, as the contract spec says (section 6.6). */
    private static boolean equalValue(String actual, String wanted) {
        return actual.equals(wanted);
    }

    /**
     * An equality every matching attribute set must satisfy, as {@code lower-case-key=value},
     * for indexing: the filter itself or an operand of a top-level {@code &} of the form
     * {@code (key=value)} without wildcard. Empty when there is none.
     */
    public java.util.Optional<String> equalityHint() {
        return java.util.Optional.ofNullable(hint);
    }

    private String hint;

    private static String squash(String s) {
        return s.replaceAll("\\s+", "").toLowerCase(Locale.ROOT);
    }

    private static final class Parser {
        private static final int MAX_DEPTH = 32;
        final String s;
        int pos;
        /** First equality found at depth 0 or directly under a top-level '&'. */
        String hint;
        private int andDepth = -1;

        Parser(String s) {
            this.s = s;
        }

        IllegalArgumentException error(String what) {
            return new IllegalArgumentException("filter '" + s + "': " + what + " at character " + (pos + 1));
        }

        Node filter(int depth) {
            if (depth > MAX_DEPTH) {
                throw error("nested deeper than " + MAX_DEPTH);
            }
            expect('(');
            if (pos >= s.length()) {
                throw error("unexpected end");
            }
            char c = s.charAt(pos);
            Node n;
            if (c == '&' || c == '|') {
                if (c == '&' && depth == 0) {
                    andDepth = 1;
                }
                pos++;
                List<Node> parts = new ArrayList<>();
                while (pos < s.length() && s.charAt(pos) == '(') {
                    parts.add(filter(depth + 1));
                }
                if (parts.isEmpty()) {
                    throw error("'" + c + "' needs at least one operand");
                }
                n = c == '&' ? a -> {
                    for (Node p : parts) {
                        if (!p.eval(a)) {
                            return false;
                        }
                    }
                    return true;
                } : a -> {
                    for (Node p : parts) {
                        if (p.eval(a)) {
                            return true;
                        }
                    }
                    return false;
                };
            } else if (c == '!') {
                pos++;
                Node inner = filter(depth + 1);
                n = a -> !inner.eval(a);
            } else {
                n = item(depth == 0 || depth == andDepth);
            }
            expect(')');
            return n;
        }

        void expect(char c) {
            if (pos >= s.length() || s.charAt(pos) != c) {
                throw error("expected '" + c + "'");
            }
            pos++;
        }

        Node item(boolean necessary) {
            int start = pos;
            while (pos < s.length() && "=<>~()".indexOf(s.charAt(pos)) < 0) {
                pos++;
            }
            String attr = s.substring(start, pos).trim();
            if (attr.isEmpty()) {
                throw error("missing attribute name");
            }
            if (pos >= s.length()) {
                throw error("unexpected end");
            }
            char op = s.charAt(pos);
            if (op == '~' || op == '<' || op == '>') {
                pos++;
                if (pos >= s.length() || s.charAt(pos) != '=') {
                    throw error("expected '=' after '" + op + "'");
                }
                pos++;
                String v = String.join("", value(false));
                return switch (op) {
                    case '~' -> a -> {
                        String x = lookup(a, attr);
                        return x != null && squash(x).equals(squash(v));
                    };
                    case '<' -> a -> {
                        String x = lookup(a, attr);
                        return x != null && compare(x, v) <= 0;
                    };
                    default -> a -> {
                        String x = lookup(a, attr);
                        return x != null && compare(x, v) >= 0;
                    };
                };
            }
            if (op != '=') {
                throw error("expected an operator");
            }
            pos++;
            List<String> pieces = value(true);
            if (pieces.size() == 1) {
                String v = pieces.get(0);
                if (necessary && hint == null) {
                    hint = attr.toLowerCase(Locale.ROOT) + "=" + v;
                }
                return a -> {
                    String x = lookup(a, attr);
                    return x != null && equalValue(x, v);
                };
            }
            if (pieces.size() == 2 && pieces.get(0).isEmpty() && pieces.get(1).isEmpty()) {
                return a -> lookup(a, attr) != null;
            }
            return a -> {
                String x = lookup(a, attr);
                return x != null && substrings(x, pieces);
            };
        }

        /** The value up to ')', split at unescaped '*' when {@code stars}. */
        List<String> value(boolean stars) {
            List<String> pieces = new ArrayList<>();
            StringBuilder cur = new StringBuilder();
            while (pos < s.length() && s.charAt(pos) != ')') {
                char c = s.charAt(pos);
                if (c == '\\') {
                    pos++;
                    if (pos >= s.length()) {
                        throw error("dangling '\\'");
                    }
                    cur.append(s.charAt(pos));
                } else if (c == '(') {
                    throw error("unescaped '(' in value");
                } else if (c == '*' && stars) {
                    pieces.add(cur.toString());
                    cur.setLength(0);
                } else {
                    cur.append(c);
                }
                pos++;
            }
            pieces.add(cur.toString());
            return pieces;
        }
    }

    private static boolean substrings(String x, List<String> pieces) {
        String first = pieces.get(0);
        String last = pieces.get(pieces.size() - 1);
        if (!x.startsWith(first)) {
            return false;
        }
        int at = first.length();
        for (int i = 1; i < pieces.size() - 1; i++) {
            int k = x.indexOf(pieces.get(i), at);
            if (k < 0) {
                return false;
            }
            at = k + pieces.get(i).length();
        }
        return x.length() - at >= last.length() && x.endsWith(last);
    }
}
