package org.arflex.drcr.impl.supervisor;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.file.Files;
import java.nio.file.Path;
import java.nio.file.attribute.PosixFilePermissions;
import java.util.ArrayList;
import java.util.List;
import org.arflex.drcr.impl.abi.ControlBlock;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;

/** The DRCR's side of the native heartbeat writer (D17): off, missing, and the real library. */
class HeartbeatBridgeTest {

    /** Built by the native superbuild (rt-core), before this module in the reactor. */
    private static final Path LIB = Path.of("../../target/native/lib/libarflex_beat.so").toAbsolutePath().normalize();

    @TempDir
    Path tmp;

    private final List<String> log = new ArrayList<>();

    private HeartbeatBridge open(HeartbeatBridge.Entries entries, boolean enabled) {
        return HeartbeatBridge.open(entries, new VerifiedExecutables(tmp, log::add), tmp.resolve("native"), enabled, 20, 1000,
                0, log::add);
    }

    @Test
    void aLateWriterIsSaidOncePerNewLongestGap() {
        assertEquals(null, HeartbeatBridge.lateWriter(20_000_000L, 0)); // on time
        assertEquals(null, HeartbeatBridge.lateWriter(49_999_999L, 0));
        String l = HeartbeatBridge.lateWriter(73_400_000L, 0);
        assertTrue(l != null && l.contains("native heartbeat writer ran 73 ms after its round before"), l);
        assertEquals(null, HeartbeatBridge.lateWriter(73_400_000L, 73_400_000L)); // said already
        assertTrue(HeartbeatBridge.lateWriter(120_000_000L, 73_400_000L).contains("120 ms"));
    }

    @Test
    void offWhenTurnedOffAndSaysWhatThatMeans() {
        HeartbeatBridge b = open(e -> {
            throw new AssertionError("looked for " + e + " although off");
        }, false);
        assertFalse(b.active());
        b.round(); // harmless
        assertTrue(log.get(0).contains("arflex.heartbeat.native=false") && log.get(0).contains("safe mode"), log.toString());
    }

    @Test
    void aBundleWithoutTheLibraryLeavesTheJavaRound() {
        HeartbeatBridge b = open(e -> null, true);
        assertFalse(b.active());
        assertTrue(log.get(0).contains("native heartbeat writer missing") && log.get(0).contains(HeartbeatBridge.ENTRY),
                log.toString());
    }

    @Test
    void aLibraryThatDoesNotLoadLeavesTheJavaRound() throws Exception {
        java.net.URL junk = Files.writeString(tmp.resolve("junk.so"), "not an ELF file").toUri().toURL();
        HeartbeatBridge b = open(e -> junk, true);
        assertFalse(b.active());
        assertTrue(log.get(0).contains("native heartbeat writer not started"), log.toString());
    }

    @Test
    void theRealWriterKeepsAControlBlockFreshWhileTheJvmIsAlive() throws Exception {
        // the suite builds the native tree first; a Java-only build (-Darflex.native.skip=true)
        // after none fails here rather than passing untested (D82)
        assertTrue(Files.isRegularFile(LIB), LIB + " not built: build the native tree (mvn install without -Darflex.native.skip)");
        java.net.URL lib = LIB.toUri().toURL();
        HeartbeatBridge b = open(e -> e.equals(HeartbeatBridge.ENTRY) ? lib : null, true);
        try {
            assertTrue(b.active(), log.toString());
            assertTrue(log.get(0).startsWith("arflex: native heartbeat writer every 20 ms, JVM stalls bridged up to 1000 ms"),
                    log.toString());
            Path extracted = tmp.resolve("native").resolve("libarflex_beat.so");
            assertEquals("r-x------", PosixFilePermissions.toString(Files.getPosixFilePermissions(extracted)));
            String name = "/arflex.jt" + ProcessHandle.current().pid() + ".beat.ctl";
            try (ControlBlock cb = ControlBlock.create(name, new ControlBlock.Config(1_000_000, 0, 100_000_000L, 0, 0, 0, 0, 0),
                    List.of())) {
                // the Java side writes nothing from here on: only the native writer can move it
                cb.segment().setLongRelease(ControlBlock.OFF_RUNTIME_HB, 1);
                long deadline = System.nanoTime() + 5_000_000_000L;
                while (cb.segment().getLongAcquire(ControlBlock.OFF_RUNTIME_HB) == 1) {
                    assertTrue(System.nanoTime() < deadline, "the native writer never wrote the heartbeat");
                    b.round();
                    Thread.onSpinWait();
                }
            }
            assertFalse(Files.exists(Path.of("/dev/shm" + name)), "the control block was not removed");
        } finally {
            b.close();
        }
    }
}
