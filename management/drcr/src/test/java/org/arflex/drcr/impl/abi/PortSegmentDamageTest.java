package org.arflex.drcr.impl.abi;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.channels.FileChannel;
import java.nio.file.Files;
import java.nio.file.Path;
import java.nio.file.StandardOpenOption;
import org.junit.jupiter.api.Test;

/** PortSegment.damage on a real segment: an overwritten header, a truncated or removed object. */
class PortSegmentDamageTest {

    private final String name = "/arflex.psd" + ProcessHandle.current().pid() + ".p.out.y";
    private final Path file = Path.of("/dev/shm", name);

    private PortSegment create() throws Exception {
        return PortSegment.create(name, PortSegment.METHOD_STATE, "arflex.Sample", 1, 0, 24, 1,
                PortSegment.OVERFLOW_NONE);
    }

    @Test
    void anOverwrittenHeaderIsDamageAndARestoredOneIsNot() throws Exception {
        try (PortSegment seg = create()) {
            assertNull(seg.damage());
            seg.segment().putLong(PortSegment.OFF_MAGIC, 0);
            assertTrue(seg.damage().startsWith("magic 0x0000000000000000"), seg.damage());
            seg.segment().putLong(PortSegment.OFF_MAGIC, PortSegment.MAGIC);
            assertNull(seg.damage());
            seg.segment().putInt(PortSegment.OFF_SLOT_STRIDE, PortSegment.stride(24) + 64);
            assertTrue(seg.damage().startsWith("geometry overwritten"), seg.damage());
        }
        assertFalse(Files.exists(file), "segment left behind");
    }

    @Test
    void aTruncatedSegmentIsDamageWithoutTouchingTheMapping() throws Exception {
        try (PortSegment seg = create()) {
            long size = Files.size(file);
            try (FileChannel ch = FileChannel.open(file, StandardOpenOption.WRITE)) {
                ch.truncate(0);
            }
            assertEquals("size 0 B, created with " + size + " B", seg.damage());
        }
        assertFalse(Files.exists(file), "segment left behind");
    }

    @Test
    void aRemovedSegmentIsDamage() throws Exception {
        try (PortSegment seg = create()) {
            Files.delete(file);
            assertEquals("removed from /dev/shm", seg.damage());
        }
        assertFalse(Files.exists(file));
    }
}
