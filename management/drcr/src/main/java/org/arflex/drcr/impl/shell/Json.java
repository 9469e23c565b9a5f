package org.arflex.drcr.impl.shell;

import java.lang.reflect.Array;
import java.lang.reflect.Field;
import java.lang.reflect.Modifier;
import java.util.Collection;
import java.util.Map;

/**
 * A tiny JSON writer for DTOs (public fields, arrays, boxed primitives, strings, maps). One line,
 * fields in declaration order, non-finite doubles as null. Keeps the bundle free of a JSON
 * library at runtime.
 */
public final class Json {

    private Json() {
    }

    /** The value as one line of JSON. */
    public static String write(Object o) {
        StringBuilder sb = new StringBuilder();
        value(sb, o);
        return sb.toString();
    }

    private static void value(StringBuilder sb, Object o) {
        if (o == null) {
            sb.append("null");
        } else if (o instanceof String s) {
            string(sb, s);
        } else if (o instanceof Double d) {
            sb.append(Double.isFinite(d) ? d.toString() : "null");
        } else if (o instanceof Float f) {
            sb.append(Float.isFinite(f) ? f.toString() : "null");
        } else if (o instanceof Number || o instanceof Boolean) {
            sb.append(o);
        } else if (o instanceof Character || o instanceof Enum<?>) {
            string(sb, o.toString());
        } else if (o.getClass().isArray()) {
            sb.append('[');
            int n = Array.getLength(o);
            for (int i = 0; i < n; i++) {
                if (i > 0) {
                    sb.append(',');
                }
                value(sb, Array.get(o, i));
            }
            sb.append(']');
        } else if (o instanceof Collection<?> c) {
            value(sb, c.toArray());
        } else if (o instanceof Map<?, ?> m) {
            sb.append('{');
            boolean first = true;
            for (var e : m.entrySet()) {
                if (!first) {
                    sb.append(',');
                }
                first = false;
                string(sb, String.valueOf(e.getKey()));
                sb.append(':');
                value(sb, e.getValue());
            }
            sb.append('}');
        } else {
            sb.append('{');
            boolean first = true;
            for (Field f : o.getClass().getFields()) {
                if (Modifier.isStatic(f.getModifiers())) {
                    continue;
                }
                if (!first) {
                    sb.append(',');
                }
                first = false;
                string(sb, f.getName());
                sb.append(':');
                try {
                    value(sb, f.get(o));
                } catch (IllegalAccessException e) {
                    sb.append("null");
                }
            }
            sb.append('}');
        }
    }

    private static void string(StringBuilder sb, String s) {
        sb.append('"');
        for (int i = 0; i < s.length(); i++) {
            char c = s.charAt(i);
            switch (c) {
                case '"' -> sb.append("\\\"");
                case '\\' -> sb.append("\\\\");
                case '\n' -> sb.append("\\n");
                case '\r' -> sb.append("\\r");
                case '\t' -> sb.append("\\t");
                default -> {
                    if (c < 0x20) {
                        sb.append(String.format("\\u%04x", (int) c));
                    } else {
                        sb.append(c);
                    }
                }
            }
        }
        sb.append('"');
    }
}
