package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertNotEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.List;
import org.junit.jupiter.api.Test;

/** Hangs, runtime crashes, dry runs, Felix's own update. */
class SupervisionIT {

    private static void signal(long pid, String sig) throws Exception {
        Process p = new ProcessBuilder("kill", "-" + sig, Long.toString(pid)).inheritIO().start();
        assertEquals(0, p.waitFor());
    }

    @Test
    void aHungRtHalfIsDetectedByItsHeartbeatAndRestarted() throws Exception {
        try (Runtime rt = new Runtime("hang")) {
            rt.installAndStart(CellIT.COUNTER);
            rt.awaitState("ACTIVE", CellIT.T, "sample-counter");
            long pid = rt.pid("sample-counter");
            signal(pid, "STOP"); // alive but silent: only the heartbeat can tell
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
        try (Runtime rt = new Runtime("felix-update")) {
            rt.installAndStart(CellIT.COUNTER);
            long id = rt.installAndStart(CellIT.SCALER);
            rt.awaitState("ACTIVE", CellIT.T, "sample-counter", "sample-scaler");
            long pid = rt.pid("sample-scaler");
            assertEquals("", rt.cmd("felix:update " + id));
            rt.waitUntil("sample-scaler back after Felix's update", CellIT.T,
                    () -> rt.activeWithNewPid("sample-scaler", pid));
            assertNotEquals(0L, rt.pid("sample-scaler"));
            CellIT.assertDataFlows(rt, 2.0);
        }
    }
}
