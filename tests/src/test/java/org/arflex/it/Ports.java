package org.arflex.it;

import java.io.IOException;
import java.nio.ByteOrder;
import java.nio.MappedByteBuffer;
import java.nio.channels.FileChannel;
import java.nio.file.Path;
import java.nio.file.StandardOpenOption;

/**
 * Reads an arflex.Sample state port straight from its shared-memory segment (rt-core ABI 1.0:
 * 256-byte header, slot 0 with a 64-byte slot header whose seq is odd while the writer writes,
 * then the 24-byte value: seq u64, t_ns i64, value f64).
 */
final class Ports {

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
                long s1 = b.getLong(256);
                if (s1 == 0) {
                    return null;
                }
                if ((s1 & 1) != 0) {
                    continue;
                }
                Sample v = new Sample(b.getLong(320), b.getLong(328), b.getDouble(336));
                long s2 = b.getLong(256);
                if (s1 == s2) {
                    return v;
                }
            }
            return null;
        }
    }
}
