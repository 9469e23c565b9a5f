package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertNotEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.List;
import org.junit.jupiter.api.Test;

/** Hangs, runtime crashes, dry runs, Felix's own update. */
class SupervisionIT {

    @Test
    void aHungRtHalfIsDetectedByItsHeartbeatAndRestarted() throws Exception {
        try (Runtime rt = new Runtime("hang")) {
            rt.installAndStart(CellIT.COUNTER);
            rt.awaitState("ACTIVE", CellIT.T, "sample-counter");
            long pid = rt.pid("sample-counter");
            Signals.send(pid, "STOP"); // alive but silent: only the heartbeat can tell
            rt.waitUntil("sample-counter restarted after the hang", CellIT.T,
                    () -> rt.activeWithNewPid("sample-counter", pid));
            assertTrue(rt.logContains("hung: no RT heartbeat"), rt.tail());
            assertEquals(1L, ((Number) rt.instance("sample-counter").get("restarts")).longValue());
        }
    }

    @Test
    void aNewRuntimeSweepsWhatACrashedOneLeft() throws Exception {
        String rid = "itsweep" + ProcessHandle.current().pid();
        List<String> orphans;
        try (Runtime first = new Runtime("sweep-a", rid)) {
            first.installAndStart(CellIT.COUNTER);
            first.installAndStart(CellIT.SCALER);
            first.awaitState("ACTIVE", CellIT.T, "sample-counter", "sample-scaler");
            first.crash();
            orphans = Runtime.rtProcesses(rid);
            // Orphans leave by themselves after their orphan hold (D10); the sweep is for those
            // that cannot: hung ones, stopped here before their hold ends.
            for (String o : orphans) {
                Signals.send(Long.parseLong(o.substring(0, o.indexOf(':'))), "STOP");
            }
            assertFalse(first.shmObjects().isEmpty(), "a crashed runtime leaves its objects");
        }
        assertEquals(2, orphans.size(), orphans.toString());
        try (Runtime second = new Runtime("sweep-b", rid)) {
            assertTrue(Runtime.rtProcesses(rid).isEmpty(), "orphaned RT halves must be killed: " + Runtime.rtProcesses(rid));
            assertTrue(second.shmObjects().isEmpty(), second.shmObjects().toString());
            assertTrue(second.logContains("swept stale objects"), second.tail());
            second.installAndStart(CellIT.COUNTER);
            second.awaitState("ACTIVE", CellIT.T, "sample-counter");
            second.dto(); // record the instance for the queue leak check
        }
    }

    /**
     * Issue 15, finding 2: kill -9 of the runtime. Its RT halves see their supervisor pipe close,
     * go safe, survive their log lines to the dead JVM's pipe (no SIGPIPE), hold for the
     * contract's orphan hold (2 s by default), then exit and remove their objects themselves.
     */
    /** The samples' contracts' orphan hold: fault/@orphanHold's default (ControlBlock.DEFAULT_ORPHAN_HOLD_NS). */
    static final long ORPHAN_HOLD_MS = 2_000;

    @Test
    void rtHalvesOfACrashedRuntimeHoldThenLeaveNothing() throws Exception {
        String rid = "itorphan" + ProcessHandle.current().pid();
        try (Runtime first = new Runtime("orphan", rid)) {
            first.installAndStart(CellIT.COUNTER);
            first.installAndStart(CellIT.SCALER);
            first.awaitState("ACTIVE", CellIT.T, "sample-counter", "sample-scaler");
            long t0 = System.nanoTime();
            first.crash();
            List<String> orphans = Runtime.rtProcesses(rid);
            long lookedMs = (System.nanoTime() - t0) / 1_000_000L;
            // The look must come within the hold to show it: a look after it cannot tell a half
            // that held from one that left at once, so it fails rather than passing unchecked
            // (D82: the check was dropped when the machine was slow).
            assertTrue(lookedMs < ORPHAN_HOLD_MS, "looked for the orphans " + lookedMs + " ms after the kill, after their "
                    + ORPHAN_HOLD_MS + " ms hold: whether they held cannot be seen (the test machine stalled)");
            assertEquals(2, orphans.size(), "both hold after the crash (" + lookedMs + " ms after the kill): " + orphans);
            first.waitUntil("the orphans exited and removed their objects", CellIT.T,
                    () -> Runtime.rtProcesses(rid).isEmpty() && first.shmObjects().isEmpty());
        }
    }

    @Test
    void planInstallTellsWhatInstallThenDoes() throws Exception {
        try (Runtime rt = new Runtime("plan")) {
            rt.installAndStart(CellIT.SCALER);
            rt.awaitState("UNSATISFIED", CellIT.T, "sample-scaler");
            String plan = rt.cmd("arflex:plan install " + CellIT.COUNTER.toUri());
            assertTrue(plan.lines().anyMatch(l -> l.contains("START") && l.contains("sample-counter")), plan);
            assertTrue(plan.lines().anyMatch(l -> l.contains("START") && l.contains("sample-scaler")), plan);
            assertEquals(null, rt.instance("sample-counter"), "a dry run changes nothing");
            rt.installAndStart(CellIT.COUNTER);
            rt.awaitState("ACTIVE", CellIT.T, "sample-counter", "sample-scaler");
            String un = rt.cmd("arflex:plan uninstall sample-counter");
            assertTrue(un.lines().anyMatch(l -> l.contains("STOP") && l.contains("sample-scaler")), un);
        }
    }

    @Test
    void felixUpdateGivesTheSameResultAsOurs() throws Exception {
        // a bare "update <id>" as users type it; Gogo resolves it to arflex:update, which hands
        // bundle ids to Felix
        try (Runtime rt = new Runtime("felix-update")) {
            rt.installAndStart(CellIT.COUNTER);
            long id = rt.installAndStart(CellIT.SCALER);
            rt.awaitState("ACTIVE", CellIT.T, "sample-counter", "sample-scaler");
            long pid = rt.pid("sample-scaler");
            assertEquals("", rt.cmd("update " + id));
            rt.waitUntil("sample-scaler back after Felix's update", CellIT.T,
                    () -> rt.activeWithNewPid("sample-scaler", pid));
            assertNotEquals(0L, rt.pid("sample-scaler"));
            CellIT.assertDataFlows(rt, 2.0);
        }
    }

    @Test
    void aRestartedMovingComponentDrivesNothingUntilTheOperatorResets() throws Exception {
        java.nio.file.Path moving = Jars.withContract(CellIT.COUNTER,
                java.nio.file.Files.createTempDirectory("arflex-it").resolve("moving.jar"),
                xml -> xml.replace("movesHardware=\"false\"", "movesHardware=\"true\"").replace("<ports>",
                        "<ports><in name=\"safety\" type=\"arflex.SafetyState\" typeVersion=\"1.0\" method=\"state\" safety=\"true\"/>"));
        try (Runtime rt = new Runtime("moving")) {
            rt.installAndStart(moving);
            rt.awaitState("ACTIVE", CellIT.T, "sample-counter");
            assertEquals(Boolean.FALSE, rt.instance("sample-counter").get("awaitingReset"), "the first start needs no reset");
            java.nio.file.Path port = rt.segment("sample-counter", "count");
            rt.waitUntil("first samples", CellIT.T, () -> Ports.readState(port) != null && Ports.readState(port).seq() > 3);
            long pid = rt.pid("sample-counter");
            ProcessHandle.of(pid).ifPresent(ProcessHandle::destroyForcibly);
            rt.waitUntil("sample-counter restarted", CellIT.T, () -> rt.activeWithNewPid("sample-counter", pid));
            assertEquals(Boolean.TRUE, rt.instance("sample-counter").get("awaitingReset"));
            // restarted but held in safe mode (hold): its output does not move
            long newPid = rt.pid("sample-counter");
            rt.waitUntil("the new RT half cycling", CellIT.T, () -> cycles(rt) > 20);
            Ports.Sample held = Ports.readState(port);
            long c0 = cycles(rt);
            rt.waitUntil("20 more cycles", CellIT.T, () -> cycles(rt) > c0 + 20);
            assertEquals(held, Ports.readState(port), "a component that moves hardware must hold after a restart");
            assertTrue(rt.cmd("arflex:stats sample-counter").contains("rt RUNNING"));
            String r = rt.cmd("arflex:reset sample-counter");
            assertTrue(r.contains("reset"), r);
            assertEquals(Boolean.FALSE, rt.instance("sample-counter").get("awaitingReset"));
            rt.waitUntil("output moving again after the reset", CellIT.T, () -> {
                Ports.Sample now = Ports.readState(port);
                return now != null && !now.equals(held);
            });
            assertEquals(newPid, rt.pid("sample-counter"), "the reset does not restart the process");
        }
    }

    private static long cycles(Runtime rt) {
        Object st = rt.instance("sample-counter").get("stats");
        return st instanceof java.util.Map<?, ?> m ? ((Number) m.get("cycles")).longValue() : 0;
    }

    @Test
    void aSecondRuntimeWithTheSameIdRefusesAndTouchesNothing() throws Exception {
        String rid = "itdup" + ProcessHandle.current().pid();
        try (Runtime first = new Runtime("dup-a", rid)) {
            first.installAndStart(CellIT.COUNTER);
            first.awaitState("ACTIVE", CellIT.T, "sample-counter");
            long pid = first.pid("sample-counter");
            try (Runtime second = new Runtime("dup-b", rid, false)) {
                second.waitUntil("the second DRCR to refuse", CellIT.T,
                        () -> second.logContains("is in use by the live runtime"));
            }
            assertEquals("ACTIVE", first.state("sample-counter"));
            assertEquals(pid, first.pid("sample-counter"), "the first runtime's RT half must be untouched");
            assertFalse(first.shmObjects().isEmpty());
        }
    }
}
