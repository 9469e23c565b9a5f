package org.arflex.contract;

import java.math.BigInteger;
import java.util.regex.Matcher;
import java.util.regex.Pattern;

/**
 * Value syntaxes shared by contracts and port types (spec §1.2): integers, decimals, booleans,
 * durations (§8.1) and sizes (§9.1). Every parser returns null on bad text; callers report.
 */
final class Values {
    private static final Pattern INT = Pattern.compile("[+-]?[0-9]{1,19}");
    private static final Pattern HEX = Pattern.compile("0x[0-9a-fA-F]{1,16}");
    private static final Pattern DECIMAL = Pattern.compile("[+-]?([0-9]+(\\.[0-9]*)?|\\.[0-9]+)([eE][+-]?[0-9]{1,3})?");
    private static final Pattern DURATION = Pattern.compile("([0-9]{1,15})(ns|us|ms|s)");
    private static final Pattern SIZE = Pattern.compile("([0-9]{1,15})(B|KiB|MiB|GiB|kB|MB|GB)?");
    private static final Pattern RATE = Pattern.compile("([0-9]{1,15})(B|KiB|MiB|GiB|kB|MB|GB)?(/s)?");

    private Values() {
    }

    /** A decimal or 0x-hex integer in long range, else null. */
    static Long longValue(String s) {
        if (s == null) {
            return null;
        }
        String t = s.trim();
        try {
            if (HEX.matcher(t).matches()) {
                return new BigInteger(t.substring(2), 16).longValue();
            }
            if (INT.matcher(t).matches()) {
                return Long.parseLong(t.startsWith("+") ? t.substring(1) : t);
            }
        } catch (NumberFormatException e) {
            return null;
        }
        return null;
    }

    /** A decimal integer in int range, else null. */
    static Integer integer(String s) {
        Long v = longValue(s);
        if (v == null || v < Integer.MIN_VALUE || v > Integer.MAX_VALUE || (s != null && s.trim().startsWith("0x"))) {
            return null;
        }
        return v.intValue();
    }

    /** A finite decimal number (no hex, no NaN, no suffix), else null. */
    static Double decimal(String s) {
        if (s == null || !DECIMAL.matcher(s.trim()).matches()) {
            return null;
        }
        double d = Double.parseDouble(s.trim());
        return Double.isFinite(d) ? d : null;
    }

    /** {@code true} or {@code false} exactly, else null. */
    static Boolean bool(String s) {
        if ("true".equals(s)) {
            return Boolean.TRUE;
        }
        if ("false".equals(s)) {
            return Boolean.FALSE;
        }
        return null;
    }

    /** A duration {@code <integer>(ns|us|ms|s)} in nanoseconds, else null (also on overflow). */
    static Long durationNs(String s) {
        if (s == null) {
            return null;
        }
        Matcher m = DURATION.matcher(s.trim());
        if (!m.matches()) {
            return null;
        }
        long v = Long.parseLong(m.group(1));
        long mul = switch (m.group(2)) {
            case "ns" -> 1L;
            case "us" -> 1_000L;
            case "ms" -> 1_000_000L;
            default -> 1_000_000_000L;
        };
        try {
            return Math.multiplyExact(v, mul);
        } catch (ArithmeticException e) {
            return null;
        }
    }

    /** A size {@code <integer>[B|KiB|MiB|GiB|kB|MB|GB]} in bytes, else null. */
    static Long size(String s) {
        return scaled(s, SIZE);
    }

    /** A rate {@code <integer>[unit][/s]} in bytes per second, else null. */
    static Long rate(String s) {
        return scaled(s, RATE);
    }

    private static Long scaled(String s, Pattern p) {
        if (s == null) {
            return null;
        }
        Matcher m = p.matcher(s.trim());
        if (!m.matches()) {
            return null;
        }
        long v = Long.parseLong(m.group(1));
        String u = m.group(2) == null ? "B" : m.group(2);
        long mul = switch (u) {
            case "KiB" -> 1L << 10;
            case "MiB" -> 1L << 20;
            case "GiB" -> 1L << 30;
            case "kB" -> 1_000L;
            case "MB" -> 1_000_000L;
            case "GB" -> 1_000_000_000L;
            default -> 1L;
        };
        try {
            return Math.multiplyExact(v, mul);
        } catch (ArithmeticException e) {
            return null;
        }
    }

    /** Formats nanoseconds with the largest unit that divides it exactly. */
    static String formatDuration(long ns) {
        if (ns != 0 && ns % 1_000_000_000L == 0) {
            return ns / 1_000_000_000L + "s";
        }
        if (ns != 0 && ns % 1_000_000L == 0) {
            return ns / 1_000_000L + "ms";
        }
        if (ns != 0 && ns % 1_000L == 0) {
            return ns / 1_000L + "us";
        }
        return ns + "ns";
    }

    /** Formats bytes with the largest binary unit that divides it exactly. */
    static String formatSize(long b) {
        if (b != 0 && b % (1L << 30) == 0) {
            return (b >> 30) + "GiB";
        }
        if (b != 0 && b % (1L << 20) == 0) {
            return (b >> 20) + "MiB";
        }
        if (b != 0 && b % (1L << 10) == 0) {
            return (b >> 10) + "KiB";
        }
        return b + "B";
    }

    /** Trimmed text, with runs of white space collapsed; empty for null. */
    static String text(String s) {
        return s == null ? "" : s.trim().replaceAll("\\s+", " ");
    }
}
