package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.file.Files;
import java.nio.file.Path;
import java.util.List;
import java.util.concurrent.Executors;
import java.util.concurrent.ScheduledExecutorService;
import java.util.concurrent.TimeUnit;
import java.util.concurrent.atomic.AtomicLong;
import org.junit.jupiter.api.Test;

/**
 * Issue 17 finding 1, "the actor never waits on a process": a frozen RT half (SIGSTOP) is
 * uninstalled, and 0.5 s later another component is killed -9. Its death is logged within its
 * normal latency, the shell answers meanwhile, the frozen one is killed and reported as such,
 * and nothing is left behind (Runtime.close). Before: the death was logged 11.6 s later and the
 * shell was frozen the whole time.
 */
class FrozenStopIT {

    /** Waits (deadline) until a log line after {@code mark} contains every text; returns when it was seen (nanoTime). */
    private static long awaitLog(Runtime rt, int mark, long timeoutMs, String... texts) {
        long deadline = System.nanoTime() + timeoutMs * 1_000_000L;
        while (System.nanoTime() - deadline < 0) {
            for (String l : rt.logSince(mark)) {
                boolean all = true;
                for (String t : texts) {
                    all &= l.contains(t);
                }
                if (all) {
                    return System.nanoTime();
                }
            }
            java.util.concurrent.locks.LockSupport.parkNanos(2_000_000); // poll of a condition with a deadline
        }
        throw new AssertionError("no log line with " + List.of(texts) + " within " + timeoutMs + " ms\n" + rt.tail());
    }

    @Test
    void aFrozenHalfBeingUninstalledHoldsNeitherCrashHandlingNorTheShell() throws Exception {
        // The scaler's own hang detection (1 s) must not beat the uninstall to it on a slow machine.
        Path scalerJar = Jars.withContract(CellIT.SCALER, Files.createTempDirectory("arflex-it").resolve("scaler.jar"),
                xml -> xml.replace("heartbeatTimeout=\"1s\"", "heartbeatTimeout=\"20s\""));
        ScheduledExecutorService timer = Executors.newSingleThreadScheduledExecutor();
        try (Runtime rt = new Runtime("frozen-stop")) {
            rt.installAndStart(CellIT.COUNTER);
            long scaler = rt.installAndStart(scalerJar);
            rt.awaitState("ACTIVE", CellIT.T, "sample-counter", "sample-scaler");
            long scalerPid = rt.pid("sample-scaler");
            long counterPid = rt.pid("sample-counter");
            Signals.send(scalerPid, "STOP"); // alive, holds its mailbox unanswered
            int mark = rt.logMark();
            AtomicLong killedAt = new AtomicLong();
            long t0 = System.nanoTime();
            // kill -9 of the other component 0.5 s after the uninstall was typed, whether or not it returned
            var kill = timer.schedule(() -> {
                killedAt.set(System.nanoTime());
                ProcessHandle.of(counterPid).ifPresent(ProcessHandle::destroyForcibly);
            }, 500, TimeUnit.MILLISECONDS);
            assertEquals("", rt.cmd("uninstall " + scaler));
            long uninstallMs = (System.nanoTime() - t0) / 1_000_000L;
            kill.get(10, TimeUnit.SECONDS);
            long seen = awaitLog(rt, mark, 30_000, "sample-counter (pid " + counterPid + ")", "killed by signal 9");
            long deathMs = (seen - killedAt.get()) / 1_000_000L;
            long l0 = System.nanoTime();
            String list = rt.cmd("arflex:list");
            long listMs = (System.nanoTime() - l0) / 1_000_000L;
            System.out.printf("FrozenStopIT: uninstall of the frozen half returned after %d ms; kill -9 of sample-counter "
                    + "logged %d ms after the kill; arflex:list answered in %d ms%n", uninstallMs, deathMs, listMs);
            long stopSeen = awaitLog(rt, mark, 30_000, "arflex: sample-scaler ", " stopped: ");
            System.out.printf("FrozenStopIT: the frozen half's stop logged %d ms after the uninstall was typed%n",
                    (stopSeen - t0) / 1_000_000L);
            assertTrue(deathMs < 2_000, "death logged after " + deathMs + " ms\n" + rt.tail());
            assertTrue(listMs < 1_000, "arflex:list took " + listMs + " ms");
            assertTrue(list.contains("sample-counter"), list);
            String stopLine = rt.logSince(mark).stream().filter(l -> l.contains("arflex: sample-scaler ") && l.contains(" stopped: "))
                    .findFirst().orElseThrow();
            assertTrue(stopLine.contains("killed after"), stopLine);
            rt.waitUntil("the frozen half gone", CellIT.T, () -> ProcessHandle.of(scalerPid).isEmpty()
                    && Runtime.rtProcesses(rt.rid).stream().noneMatch(p -> p.contains("--instance sample-scaler ")));
            assertNull(rt.instance("sample-scaler"));
            rt.waitUntil("sample-counter restarted", CellIT.T, () -> rt.activeWithNewPid("sample-counter", counterPid));
        } finally {
            timer.shutdownNow();
        }
    }
}
