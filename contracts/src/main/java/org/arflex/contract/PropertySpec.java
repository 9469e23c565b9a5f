package org.arflex.contract;

import java.util.Optional;

/**
 * A typed parameter of a component. Values live in the control block's parameter table and are
 * applied by the RT thread at a cycle boundary.
 *
 * @param name         parameter name, unique within its contract ({@code [a-z][a-z0-9_.]{0,30}})
 * @param type         value type
 * @param defaultValue default, already checked against type and range
 * @param min          inclusive lower bound for numeric types
 * @param max          inclusive upper bound for numeric types
 * @param unit         unit text (SI symbols, for display), may be empty
 * @param mutable      may be changed while the component is Active
 * @param description  free text, may be empty
 */
public record PropertySpec(
        String name,
        Type type,
        Value defaultValue,
        Optional<Double> min,
        Optional<Double> max,
        String unit,
        boolean mutable,
        String description) {

    /** Parameter value types; the control block stores each in 8 bytes. */
    public enum Type { BOOL, INT, DOUBLE }

    /**
     * A parameter value, stored as in the control block: {@code long} for BOOL (0/1) and INT,
     * IEEE 754 bits for DOUBLE.
     */
    public record Value(Type type, long bits) {
        /** A double value. */
        public static Value ofDouble(double d) {
            return new Value(Type.DOUBLE, Double.doubleToRawLongBits(d));
        }

        /** An integer value. */
        public static Value ofInt(long v) {
            return new Value(Type.INT, v);
        }

        /** A boolean value. */
        public static Value ofBool(boolean b) {
            return new Value(Type.BOOL, b ? 1 : 0);
        }

        /** The value as a double, whatever its type. */
        public double asDouble() {
            return type == Type.DOUBLE ? Double.longBitsToDouble(bits) : bits;
        }

        @Override
        public String toString() {
            return switch (type) {
                case BOOL -> bits != 0 ? "true" : "false";
                case INT -> Long.toString(bits);
                case DOUBLE -> Double.toString(Double.longBitsToDouble(bits));
            };
        }
    }
}
