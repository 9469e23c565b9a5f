package org.arflex.drcr.dto;

/** Since 0.3.0: one decoded field of a port value ({@link PortValueDTO}). */
public class PortFieldDTO {
    /** Field name as in the port type definition. */
    public String name;
    /** Unit text from the definition, may be empty. */
    public String unit;
    /** Element type: u8, u16, u32, u64, i32, i64, f32 or f64. */
    public String scalar;
    /** Elements in the field (1 for a scalar). */
    public int count;
    /**
     * The values as doubles (u64 and i64 above 2^53 lose precision), at most
     * {@link #MAX_VALUES} of them: a longer array is cut and {@link #truncated} is set.
     */
    public double[] values;
    /** True when {@link #values} holds fewer than {@link #count} elements. */
    public boolean truncated;

    /** Most elements copied per field. */
    public static final int MAX_VALUES = 64;
}
