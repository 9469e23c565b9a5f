package org.arflex.drcr.impl.runtime;

import static org.junit.jupiter.api.Assertions.assertArrayEquals;
import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.nio.ByteBuffer;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.Arrays;
import org.arflex.contract.PortTypes;
import org.arflex.contract.PortType;
import org.arflex.drcr.dto.PortFieldDTO;
import org.arflex.drcr.impl.abi.PortReader;
import org.arflex.drcr.impl.abi.PortSegment;
import org.junit.jupiter.api.Test;

/**
 * Port values as the console reads them: real segments written the way a producer writes them
 * (ABI.md §4), read back through a read-only mapping and decoded with the type definition.
 */
class PortValuesTest {

    private final String rid = "pv" + ProcessHandle.current().pid();
    private final PortTypes types = PortTypes.builtin();

    /** Writes element {@code i} into its slot as the C producer does. */
    private static void write(PortSegment seg, long i, int depth, long stamp, byte[] payload) {
        ByteBuffer b = seg.segment().buffer();
        int stride = PortSegment.stride(payload.length);
        int at = PortSegment.HDR_SIZE + (int) (i % depth) * stride;
        seg.segment().setLongRelease(at, 2 * i + 1);
        b.putLong(at + 8, stamp);
        b.put(at + PortSegment.SLOT_HDR_SIZE, payload);
        seg.segment().setLongRelease(at, 2 * i + 2);
        seg.segment().setLongRelease(PortSegment.OFF_HEAD, i + 1);
    }

    private static byte[] sample(long seq, long t, double v) {
        ByteBuffer b = ByteBuffer.allocate(24).order(java.nio.ByteOrder.LITTLE_ENDIAN);
        b.putLong(0, seq).putLong(8, t).putDouble(16, v);
        return b.array();
    }

    @Test
    void stateValueIsCopiedAndDecodedWithoutWritingTheSegment() throws Exception {
        String name = "/arflex." + rid + ".src.out.y";
        try (PortSegment seg = PortSegment.create(name, PortSegment.METHOD_STATE, "arflex.Sample", 1, 0, 24, 1,
                PortSegment.OVERFLOW_NONE)) {
            PortReader.Value none = PortReader.readNewest(name, "arflex.Sample", 24);
            assertEquals(-1, none.index(), "nothing published yet");
            write(seg, 0, 1, 111, sample(1, 111, 0.5));
            write(seg, 1, 1, 222, sample(2, 222, -3.25));
            byte[] before = snapshot(seg);
            PortReader.Value v = PortReader.readNewest(name, "arflex.Sample", 24);
            assertEquals(1, v.index());
            assertEquals(222, v.stampNs());
            assertEquals(2, v.published());
            assertArrayEquals(before, snapshot(seg), "the reader must not write the segment");
            PortType t = types.find("arflex.Sample").orElseThrow();
            PortFieldDTO[] f = PortValues.decode(t, ByteBuffer.wrap(v.payload()).order(java.nio.ByteOrder.LITTLE_ENDIAN));
            assertEquals("seq,t_ns,value", String.join(",", Arrays.stream(f).map(x -> x.name).toList()));
            assertEquals(2.0, f[0].values[0]);
            assertEquals(-3.25, f[2].values[0]);
            assertEquals("f64", f[2].scalar);
        }
    }

    /** Port ABI 2.0 (DECISIONS.md D30): the value follows the 24-byte slot header in slot 0's first
     *  cache line, and a segment of another layout major (a 1.x one had its payload at +64) is refused
     *  with a message naming both versions, never misread. */
    @Test
    void abi2LayoutIsReadAndA1xSegmentIsRefused() throws Exception {
        assertEquals(2, PortSegment.ABI_MAJOR);
        assertEquals(24, PortSegment.SLOT_HDR_SIZE);
        assertEquals(64, PortSegment.stride(40));
        assertEquals(128, PortSegment.stride(41));
        String name = "/arflex." + rid + ".src.out.v";
        try (PortSegment seg = PortSegment.create(name, PortSegment.METHOD_STATE, "arflex.Sample", 1, 0, 24, 1,
                PortSegment.OVERFLOW_NONE)) {
            ByteBuffer b = seg.segment().buffer();
            assertEquals(2, b.getShort(PortSegment.OFF_ABI_MAJOR));
            assertEquals(0, b.getShort(PortSegment.OFF_ABI_MINOR));
            assertEquals(64, b.getInt(PortSegment.OFF_SLOT_STRIDE));
            write(seg, 0, 1, 7, sample(5, 7, 1.5));
            assertEquals(5, b.getLong(PortSegment.HDR_SIZE + 24), "payload right after the 24-byte slot header");
            assertEquals(0, PortReader.readNewest(name, "arflex.Sample", 24).index());
            b.putShort(PortSegment.OFF_ABI_MAJOR, (short) 1);
            b.putShort(PortSegment.OFF_ABI_MINOR, (short) 2);
            IOException e = assertThrows(IOException.class, () -> PortReader.readNewest(name, "arflex.Sample", 24));
            assertTrue(e.getMessage().contains("port ABI 1.2") && e.getMessage().contains("reads 2.x"), e.getMessage());
            b.putShort(PortSegment.OFF_ABI_MAJOR, (short) 3);
            assertThrows(IOException.class, () -> PortReader.readNewest(name, "arflex.Sample", 24));
        }
    }

    @Test
    void streamIsPeekedAtTheNewestSlotNeverConsumed() throws Exception {
        String name = "/arflex." + rid + ".src.out.s";
        try (PortSegment seg = PortSegment.create(name, PortSegment.METHOD_STREAM, "arflex.Sample", 1, 0, 24, 4,
                PortSegment.OVERFLOW_DROP_OLDEST)) {
            for (int i = 0; i < 6; i++) {
                write(seg, i, 4, 1000 + i, sample(i, 1000 + i, i * 1.5));
            }
            PortReader.Value v = PortReader.readNewest(name, "arflex.Sample", 24);
            assertEquals(5, v.index());
            assertEquals(1005, v.stampNs());
            assertEquals(0, seg.segment().getLongAcquire(PortSegment.OFF_TAIL), "tail untouched");
        }
    }

    @Test
    void aWriteInProgressGivesNoValueAndAWrongTypeIsNamed() throws Exception {
        String name = "/arflex." + rid + ".src.out.w";
        try (PortSegment seg = PortSegment.create(name, PortSegment.METHOD_STATE, "arflex.Sample", 1, 0, 24, 1,
                PortSegment.OVERFLOW_NONE)) {
            write(seg, 0, 1, 5, sample(0, 5, 1));
            seg.segment().setLongRelease(PortSegment.HDR_SIZE, 3); // writer stuck mid-write
            assertEquals(-1, PortReader.readNewest(name, "arflex.Sample", 24).index());
            IOException e = assertThrows(IOException.class, () -> PortReader.readNewest(name, "arflex.Pose", 24));
            assertTrue(e.getMessage().contains(name) && e.getMessage().contains("arflex.Pose"), e.getMessage());
        }
        IOException gone = assertThrows(IOException.class, () -> PortReader.readNewest(name, "arflex.Sample", 24));
        assertTrue(gone.getMessage().contains(name), gone.getMessage());
        assertFalse(Files.exists(Path.of("/dev/shm" + name)));
    }

    private static byte[] snapshot(PortSegment seg) {
        ByteBuffer b = seg.segment().buffer();
        byte[] out = new byte[PortSegment.HDR_SIZE + PortSegment.stride(24)];
        b.get(0, out);
        return out;
    }
}
