package org.arflex.drcr.impl.runtime;

import org.arflex.contract.PropertySpec;

/**
 * Parsing, range checking and formatting of parameter values (8-byte control block encoding).
 * Public for {@link #parse}: a deployment set checks its parameter writes before anything is
 * installed (D50).
 */
public final class Params {

    private Params() {
    }

    /**
     * Parses {@code text} for {@code p} and checks its range.
     *
     * @throws IllegalArgumentException naming the parameter, the value and the rule
     */
    public static long parse(PropertySpec p, String text) {
        String t = text.trim();
        long bits;
        double numeric;
        switch (p.type()) {
            case BOOL -> {
                if (t.equalsIgnoreCase("true") || t.equals("1")) {
                    bits = 1;
                } else if (t.equalsIgnoreCase("false") || t.equals("0")) {
                    bits = 0;
                } else {
                    throw new IllegalArgumentException(p.name() + ": '" + text + "' is not a bool (true/false)");
                }
                return bits;
            }
            case INT -> {
                try {
                    bits = Long.parseLong(t);
                } catch (NumberFormatException e) {
                    throw new IllegalArgumentException(p.name() + ": '" + text + "' is not an integer");
                }
                numeric = bits;
            }
            case DOUBLE -> {
                try {
                    numeric = Double.parseDouble(t);
                } catch (NumberFormatException e) {
                    throw new IllegalArgumentException(p.name() + ": '" + text + "' is not a number");
                }
                if (!Double.isFinite(numeric)) {
                    throw new IllegalArgumentException(p.name() + ": '" + text + "' is not finite");
                }
                bits = Double.doubleToRawLongBits(numeric);
            }
            default -> throw new IllegalArgumentException(p.name() + ": unknown type " + p.type());
        }
        if (p.min().isPresent() && numeric < p.min().get() || p.max().isPresent() && numeric > p.max().get()) {
            throw new IllegalArgumentException(p.name() + ": " + text + " is out of range ["
                    + p.min().map(String::valueOf).orElse("-inf") + ", " + p.max().map(String::valueOf).orElse("inf")
                    + "]" + (p.unit().isEmpty() ? "" : " " + p.unit()));
        }
        return bits;
    }

    static String format(PropertySpec p, long bits) {
        return new PropertySpec.Value(p.type(), bits).toString();
    }
}
