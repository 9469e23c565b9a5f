package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.file.Files;
import java.nio.file.Path;
import java.util.regex.Matcher;
import java.util.regex.Pattern;
import org.junit.jupiter.api.Test;

/**
 * Issue 15: a stall of the runtime JVM is not a lost supervisor (DECISIONS.md D17). A stall of
 * every Java thread shorter than the heartbeat grace (here: a heap dump, which holds the whole
 * JVM at a safepoint, injected from outside with jcmd) is bridged by the native heartbeat
 * writer: no moving component goes to safe mode or latches a reset. A stopped JVM (SIGSTOP)
 * stops the writer too: the arm holds within the heartbeat timeout and waits for a reset.
 */
class JvmStallIT {

    private static final Pattern SILENT = Pattern.compile("heartbeat round was silent for (\\d+) ms \\(longest yet\\); (.*)");
    /** A stall worth the name: past the components' 100 ms heartbeat timeout. */
    private static final long STALL_MS = 150;

    static Path movingCounter() throws Exception {
        return Jars.withContract(CellIT.COUNTER, Files.createTempDirectory("arflex-it").resolve("moving.jar"),
                xml -> xml.replace("movesHardware=\"false\"", "movesHardware=\"true\"").replace("<ports>",
                        "<ports><in name=\"safety\" type=\"arflex.SafetyState\" typeVersion=\"1.0\" method=\"state\" safety=\"true\"/>"));
    }

    private static Path ctl(Runtime rt) {
        return Path.of("/dev/shm/arflex." + rt.rid + ".sample-counter.ctl");
    }

    /** Holds every Java thread of the runtime at a safepoint while the heap is written out. */
    private static void heapDump(long jvm, Path file) throws Exception {
        Jcmd.run(jvm, "GC.heap_dump", "-all", "-gz=9", file.toString());
        Files.deleteIfExists(file);
    }

    private static long longestStall(Runtime rt) {
        long max = 0;
        for (String l : rt.logSince(0)) {
            Matcher m = SILENT.matcher(l);
            if (m.find()) {
                max = Math.max(max, Long.parseLong(m.group(1)));
            }
        }
        return max;
    }

    /** Starts the moving counter and waits for its output to move. */
    private static Path movingAndActive(Runtime rt) throws Exception {
        rt.installAndStart(movingCounter());
        rt.awaitState("ACTIVE", CellIT.T, "sample-counter");
        Path port = rt.segment("sample-counter", "count");
        rt.waitUntil("first samples", CellIT.T, () -> Ports.readState(port) != null && Ports.readState(port).seq() > 3);
        return port;
    }

    /** Heap dumps until one held the JVM for {@code ms} (the runtime logs each new longest silence). */
    private static long stallAtLeast(Runtime rt, long ms) throws Exception {
        long jvm = rt.jvmPid();
        Path dump = Files.createTempDirectory("arflex-it").resolve("stall.hprof");
        int dumps = 0;
        while (longestStall(rt) < ms && dumps < 10) {
            heapDump(jvm, dump);
            dumps++;
        }
        Files.deleteIfExists(dump.getParent());
        long stall = longestStall(rt);
        System.out.printf("JvmStallIT: longest JVM stall %d ms after %d heap dumps%n", stall, dumps);
        assertTrue(stall >= ms, "no heap dump held the JVM for " + ms + " ms (longest " + stall + " ms)");
        return stall;
    }

    @Test
    void aJvmStallWithinTheGraceMovesNoComponentToSafeMode() throws Exception {
        // a grace longer than any heap dump here: the stall is past the 100 ms timeout, within the grace
        try (Runtime rt = Runtime.withProperties("jvm-stall", "arflex.heartbeat.grace.ms=60000")) {
            assertTrue(rt.logContains("native heartbeat writer every"), "the native writer did not start:\n" + rt.tail());
            Path port = movingAndActive(rt);
            stallAtLeast(rt, STALL_MS);
            assertTrue(rt.logContains("the native writer bridged it"), rt.tail());
            int flags = CellPorts.ctlFlags(ctl(rt));
            assertEquals(0, flags & (CellPorts.FLAG_SAFE_ACTIVE | CellPorts.FLAG_RESET_REQUIRED),
                    "a bridged JVM stall must not put the moving component in safe mode (flags " + flags + ")");
            assertEquals(Boolean.FALSE, rt.instance("sample-counter").get("awaitingReset"));
            assertEquals(Boolean.FALSE, rt.instance("sample-counter").get("safeMode"));
            long seq = Ports.readState(port).seq();
            rt.waitUntil("the output moving on", CellIT.T, () -> Ports.readState(port).seq() > seq + 10);
        }
    }

    @Test
    void aJvmStallPastTheGraceHoldsTheArmUntilAReset() throws Exception {
        try (Runtime rt = Runtime.withProperties("jvm-stall-long", "arflex.heartbeat.grace.ms=100")) {
            movingAndActive(rt);
            // past the grace and then the component's 100 ms timeout
            stallAtLeast(rt, 100 + STALL_MS);
            assertTrue(rt.logContains("over the grace of 100 ms: the heartbeat was withheld"), rt.tail());
            assertTrue((CellPorts.ctlFlags(ctl(rt)) & CellPorts.FLAG_RESET_REQUIRED) != 0,
                    "a moving component latches a reset when its supervisor was silent past the grace");
            rt.waitUntil("the DRCR showing the wait for a reset", CellIT.T,
                    () -> Boolean.TRUE.equals(rt.instance("sample-counter").get("awaitingReset")));
        }
    }

    @Test
    void aStoppedJvmStillHoldsTheArmUntilAReset() throws Exception {
        try (Runtime rt = new Runtime("jvm-stop")) {
            movingAndActive(rt);
            long jvm = rt.jvmPid();
            Signals.send(jvm, "STOP");
            try {
                rt.waitUntil("the RT half in safe mode while its JVM is stopped", CellIT.T,
                        () -> (CellPorts.ctlFlags(ctl(rt)) & CellPorts.FLAG_SAFE_ACTIVE) != 0);
            } finally {
                Signals.send(jvm, "CONT");
            }
            assertTrue((CellPorts.ctlFlags(ctl(rt)) & CellPorts.FLAG_RESET_REQUIRED) != 0,
                    "a moving component latches a reset when its supervisor was silent");
            rt.waitUntil("the DRCR showing the wait for a reset", CellIT.T,
                    () -> Boolean.TRUE.equals(rt.instance("sample-counter").get("awaitingReset")));
            String r = rt.cmd("arflex:reset sample-counter");
            assertTrue(r.contains("reset"), r);
            rt.waitUntil("safe mode left after the reset", CellIT.T,
                    () -> (CellPorts.ctlFlags(ctl(rt)) & (CellPorts.FLAG_SAFE_ACTIVE | CellPorts.FLAG_RESET_REQUIRED)) == 0);
        }
    }
}
