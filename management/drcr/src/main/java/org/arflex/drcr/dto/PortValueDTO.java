package org.arflex.drcr.dto;

/**
 * Since 0.3.0: the newest value of one output port, copied under the port slot's seqlock from a
 * read-only mapping of the port segment (the producer never notices the reader) and decoded
 * field by field with the port type's definition (contracts/types/*.xml).
 */
public class PortValueDTO {
    /** Producing instance. */
    public String component;
    /** Output port name. */
    public String port;
    /** Port type name, e.g. arflex.Sample. */
    public String type;
    /** Port type version MAJOR.MINOR as the contract declares it. */
    public String typeVersion;
    /** STATE, STREAM or FRAME. */
    public String method;
    /** Elements the producer published so far (the segment's head); 0 when none yet. */
    public long published;
    /** Index (0-based count of elements ever written) of the value below; -1 when none yet. */
    public long index = -1;
    /** CLOCK_MONOTONIC time the producer wrote the value, ns; 0 when none yet. */
    public long stampNs;
    /** CLOCK_MONOTONIC time the manager read it, ns. */
    public long readNs;
    /** The decoded fields of the value (pads omitted); empty when none was published yet. */
    public PortFieldDTO[] fields;
}
