package org.arflex.it;

import java.io.IOException;
import java.nio.ByteOrder;
import java.nio.MappedByteBuffer;
import java.nio.channels.FileChannel;
import java.nio.file.Path;
import java.nio.file.StandardOpenOption;
import org.arflex.drcr.impl.abi.Layout;

/**
 * Reads an arflex.Sample state port straight from its shared-memory segment (rt-core ABI: the
 * segment header, then slot 0 with its slot header whose seq is odd while the writer writes,
 * then the 24-byte value: seq u64, t_ns i64, value f64). The offsets are rt-core's, generated
 * from its headers ({@link Layout}, DECISIONS.md D22).
 */
final class Ports {

    /** Slot 0 of a state port: its seqlock word and the first byte of its value. */
    static final int SLOT0_SEQ = Layout.PORT_HDR_SIZE + Layout.OFF_SLOT_HDR_SEQ;
    static final int SLOT0_VALUE = Layout.PORT_HDR_SIZE + Layout.SLOT_HDR_SIZE;

    record Sample(long seq, long tNs, double value) {
    }

    private Ports() {
    }

    /** The current value, or null when none was written yet or every read was torn. */
    static Sample readState(Path segment) throws IOException {
        try (FileChannel ch = FileChannel.open(segment, StandardOpenOption.READ)) {
            MappedByteBuffer b = ch.map(FileChannel.MapMode.READ_ONLY, 0, 4096);
            b.order(ByteOrder.LITTLE_ENDIAN);
            for (int attempt = 0; attempt < 100; attempt++) {
                long s1 = b.getLong(SLOT0_SEQ);
                if (s1 == 0) {
                    return null;
                }
                if ((s1 & 1) != 0) {
                    continue;
                }
                Sample v = new Sample(b.getLong(SLOT0_VALUE), b.getLong(SLOT0_VALUE + 8), b.getDouble(SLOT0_VALUE + 16));
                long s2 = b.getLong(SLOT0_SEQ);
                if (s1 == s2) {
                    return v;
                }
            }
            return null;
        }
    }
}
