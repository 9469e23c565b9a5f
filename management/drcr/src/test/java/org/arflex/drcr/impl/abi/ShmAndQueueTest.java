package org.arflex.drcr.impl.abi;

import static org.junit.jupiter.api.Assertions.assertArrayEquals;
import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.nio.file.Files;
import java.nio.file.Path;
import java.nio.file.attribute.PosixFilePermissions;
import java.util.List;
import org.junit.jupiter.api.Test;

/** Real shm and mq objects through JNA: created exclusive with 0600, removed on close. */
class ShmAndQueueTest {

    private final String rid = "jt" + ProcessHandle.current().pid();

    @Test
    void controlBlockIsCreatedExclusive0600AndRemoved() throws Exception {
        String name = "/arflex." + rid + ".unit.ctl";
        Path file = Path.of("/dev/shm" + name);
        ControlBlock.Param gain = new ControlBlock.Param("gain", ControlBlock.PARAM_DOUBLE, true,
                Double.doubleToRawLongBits(0.0), Double.doubleToRawLongBits(10.0), Double.doubleToRawLongBits(2.5));
        try (ControlBlock cb = ControlBlock.create(name, new ControlBlock.Config(1_000_000, 1_000_000, 500_000_000L, 1,
                10, 0, 0, ControlBlock.CFG_MOVES_HARDWARE), List.of(gain), true)) {
            assertTrue(Files.exists(file));
            assertEquals("rw-------", PosixFilePermissions.toString(Files.getPosixFilePermissions(file)));
            assertEquals(ControlBlock.SIZE, Files.size(file));
            assertThrows(IOException.class, () -> ControlBlock.create(name, new ControlBlock.Config(1, 1, 0, 0, 0, 0, 0, 0),
                    List.of()), "second create of the same name must fail (O_EXCL)");
            assertEquals(0, cb.paramIndex("gain"));
            assertEquals(-1, cb.paramIndex("nope"));
            assertEquals(2.5, Double.longBitsToDouble(cb.paramValue(0)));
            assertEquals(ControlBlock.FLAG_RESET_REQUIRED, cb.flags());
            assertEquals(ControlBlock.STATE_CREATED, cb.state());
            long seq = cb.requestParam(0, Double.doubleToRawLongBits(3.0));
            assertEquals(2, seq);
            assertEquals(ControlBlock.MAGIC, cb.segment().getLong(0));
            ControlBlock.Stats st = cb.stats(1000);
            assertEquals(0, st.cycles());
        }
        assertFalse(Files.exists(file), "close must unlink " + file);
    }

    @Test
    void queueRoundTripAndTimeout() throws Exception {
        String name = "/arflex." + rid + ".unit.cmd";
        Path file = Path.of("/dev/mqueue" + name);
        try (MessageQueue q = MessageQueue.create(name, 10, 256)) {
            assertTrue(MessageQueue.exists(name));
            if (Files.isDirectory(Path.of("/dev/mqueue"))) {
                assertEquals("rw-------", PosixFilePermissions.toString(Files.getPosixFilePermissions(file)));
            }
            q.send(new byte[] {1, 2, 3}, 100);
            assertArrayEquals(new byte[] {1, 2, 3}, q.receive(100).orElseThrow());
            assertTrue(q.receive(10).isEmpty());
            assertThrows(IOException.class, () -> MessageQueue.create(name, 10, 256));
        }
        assertFalse(MessageQueue.exists(name), "close must unlink " + name);
    }
}
