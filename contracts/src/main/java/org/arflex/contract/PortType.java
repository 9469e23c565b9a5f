package org.arflex.contract;

import java.nio.ByteBuffer;
import java.nio.ByteOrder;
import java.nio.charset.StandardCharsets;
import java.util.ArrayList;
import java.util.List;
import java.util.Optional;
import java.util.Set;

/**
 * A port type: a fixed-width little-endian layout with a name and a {@code major.minor} version
 * (spec §13). Defined in contracts/types/*.xml; the C header and the Java accessor are
 * generated from it. Instances come from {@link PortTypes}.
 *
 * @param name        qualified name, for example {@code arflex.JointState}
 * @param version     layout version; a provider of P feeds a consumer of C when same major, P.minor >= C.minor
 * @param methods     transport methods a port of this type may use
 * @param fields      fields and explicit pads in layout order, with their offsets
 * @param constants   named values of fields (enumerations, flags)
 * @param size        size of one value, bytes (a multiple of 8)
 * @param maxPayload  for frame types: largest payload after the header in one slot, bytes; 0 otherwise
 * @param description free text
 * @param source      where the definition was read from
 */
public record PortType(String name, TypeVersion version, Set<PortSpec.Method> methods, List<Field> fields,
        List<Constant> constants, int size, long maxPayload, String description, String source) {

    public PortType {
        methods = Set.copyOf(methods);
        fields = List.copyOf(fields);
        constants = List.copyOf(constants);
    }

    /**
     * The 64-bit type id shared by C and Java: FNV-1a 64 of the name, as rt-core's
     * {@code arflex_port_type_hash} (spec §13.3); the version travels beside it.
     */
    public long id() {
        return fnv1a64(name);
    }

    /** The field of that name (pads excluded). */
    public Optional<Field> field(String fieldName) {
        return fields.stream().filter(f -> !f.padding() && f.name().equals(fieldName)).findFirst();
    }

    /** FNV-1a 64-bit hash of the UTF-8 bytes of {@code text}. */
    public static long fnv1a64(String text) {
        long h = 0xcbf29ce484222325L;
        for (byte b : text.getBytes(StandardCharsets.UTF_8)) {
            h ^= b & 0xff;
            h *= 0x100000001b3L;
        }
        return h;
    }

    /** Scalar element types; each is aligned to its own size (spec §13.2). */
    public enum Scalar {
        U8(1, "uint8_t"), U16(2, "uint16_t"), U32(4, "uint32_t"), U64(8, "uint64_t"),
        I32(4, "int32_t"), I64(8, "int64_t"), F32(4, "float"), F64(8, "double");

        private final int size;
        private final String cType;

        Scalar(int size, String cType) {
            this.size = size;
            this.cType = cType;
        }

        /** Size and alignment in bytes. */
        public int size() {
            return size;
        }

        /** The C type. */
        public String cType() {
            return cType;
        }

        /** The spelling in definitions ({@code u8} ... {@code f64}). */
        public String xmlName() {
            return name().toLowerCase(java.util.Locale.ROOT);
        }
    }

    /**
     * A field (or explicit pad) of a layout.
     *
     * @param name        field name; pads are named {@code _padN}
     * @param scalar      element type (U8 for pads)
     * @param count       number of elements, 1 for a scalar
     * @param array       declared with {@code count} (an array, even of 1)
     * @param offset      byte offset from the start of the value
     * @param padding     true for an explicit pad
     * @param unit        unit text, may be empty
     * @param description free text
     * @param bounds      what a valid value of each element is ({@link Bounds#NONE} when nothing is declared)
     */
    public record Field(String name, Scalar scalar, int count, boolean array, int offset, boolean padding,
            String unit, String description, Bounds bounds) {
        public Field {
            bounds = bounds == null ? Bounds.NONE : bounds;
        }

        /** Size in bytes. */
        public int size() {
            return scalar.size() * count;
        }
    }

    /**
     * Validation metadata of a floating-point field (spec §13.2): every element must be finite
     * (no NaN, no infinity) when {@code finite}, and within {@code min..max} when declared (a NaN
     * is never within a range). Not part of the layout: it changes neither size, offsets nor the
     * type id, so adding it is no version change (§13.4).
     *
     * @param finite NaN and ±infinity are invalid
     * @param min    smallest valid value, {@code -Infinity} when not declared
     * @param max    largest valid value, {@code +Infinity} when not declared
     */
    public record Bounds(boolean finite, double min, double max) {
        /** Nothing declared: every value is valid. */
        public static final Bounds NONE = new Bounds(false, Double.NEGATIVE_INFINITY, Double.POSITIVE_INFINITY);

        /** True when a lower bound was declared. */
        public boolean hasMin() {
            return min != Double.NEGATIVE_INFINITY;
        }

        /** True when an upper bound was declared. */
        public boolean hasMax() {
            return max != Double.POSITIVE_INFINITY;
        }

        /** True when anything is declared. */
        public boolean declared() {
            return finite || hasMin() || hasMax();
        }

        /** True when {@code v} is a valid element value. */
        public boolean accepts(double v) {
            if (finite && !Double.isFinite(v)) {
                return false;
            }
            return !(hasMin() || hasMax()) || (v >= min && v <= max);
        }

        /** The bounds as a reader sees them, e.g. {@code finite, 0..1}; empty for {@link #NONE}. */
        @Override
        public String toString() {
            String range = hasMin() || hasMax()
                    ? (hasMin() ? num(min) : "") + ".." + (hasMax() ? num(max) : "") : "";
            return finite ? (range.isEmpty() ? "finite" : "finite, " + range) : range;
        }

        private static String num(double d) {
            return d == Math.rint(d) && Math.abs(d) < 1e15 ? Long.toString((long) d) : Double.toString(d);
        }
    }

    /**
     * The fields of the value at byte {@code at} of {@code b} (little endian) that violate their
     * {@link Bounds}, one text per bad element ({@code power_scale = 1.5, not finite, 0..1}); empty
     * when the value is valid. For monitors and the console; the RT check is the generated C
     * function {@code arflex_<type>_valid}.
     */
    public List<String> violations(ByteBuffer b, int at) {
        ByteBuffer le = b.duplicate().order(ByteOrder.LITTLE_ENDIAN);
        List<String> out = new ArrayList<>();
        for (Field f : fields) {
            if (f.padding() || !f.bounds().declared()) {
                continue;
            }
            for (int i = 0; i < f.count(); i++) {
                int pos = at + f.offset() + i * f.scalar().size();
                double v = f.scalar() == Scalar.F32 ? le.getFloat(pos) : le.getDouble(pos);
                if (!f.bounds().accepts(v)) {
                    out.add(f.name() + (f.array() ? "[" + i + "]" : "") + " = " + v + ", not " + f.bounds());
                }
            }
        }
        return out;
    }

    /**
     * A named value.
     *
     * @param name        constant name, upper case
     * @param scalar      its type
     * @param value       its value (two's complement bits for signed, raw bits for unsigned)
     * @param description free text
     */
    public record Constant(String name, Scalar scalar, long value, String description) {
    }
}
