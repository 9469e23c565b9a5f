package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertNotEquals;
import static org.junit.jupiter.api.Assertions.assertNotNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.file.Files;
import java.nio.file.Path;
import java.util.HashMap;
import java.util.List;
import java.util.Map;
import org.junit.jupiter.api.Test;

/**
 * The cell end to end: a real Felix, real RT processes (sample-counter feeding sample-scaler),
 * real shared memory and message queues. Every test ends with the leak check of
 * {@link Runtime#close()}.
 */
class CellIT {

    static final Path COUNTER = Components.jar("sample-counter");
    static final Path SCALER = Components.jar("sample-scaler");
    static final long T = 30_000;

    /** Waits until y = gain * x holds for a sample seen on both ports (data flows through the port). */
    static void assertDataFlows(Runtime rt, double gain) {
        Map<Long, Double> xs = new HashMap<>();
        long[] matched = {0};
        rt.waitUntil("y = " + gain + " * x on the ports", T, () -> {
            Ports.Sample x = Ports.readState(rt.segment("sample-counter", "count"));
            Ports.Sample y = Ports.readState(rt.segment("sample-scaler", "y"));
            if (x != null) {
                xs.put(x.seq(), x.value());
            }
            if (y != null && xs.containsKey(y.seq()) && y.value() != 0) {
                assertEquals(gain * xs.get(y.seq()), y.value(), 1e-9, "y of seq " + y.seq());
                matched[0]++;
            }
            return matched[0] >= 3;
        });
    }

    @Test
    void consumerFirstThenProviderBothActiveAndDataFlows() throws Exception {
        try (Runtime rt = new Runtime("consumer-first")) {
            long scaler = rt.install(SCALER);
            rt.awaitState("INSTALLED", T, "sample-scaler"); // picked up when installed, not started
            assertEquals("", rt.cmd("start " + scaler));
            rt.awaitState("UNSATISFIED", T, "sample-scaler");
            String why = (String) rt.instance("sample-scaler").get("failureReason");
            assertTrue(why.contains("sample-counter"), why);
            rt.installAndStart(COUNTER);
            rt.awaitState("ACTIVE", T, "sample-counter", "sample-scaler");
            assertEquals("sample-scaler.x <- sample-counter.count", rt.cmd("arflex:bindings"));
            assertDataFlows(rt, 2.0);
            assertEquals("sample-scaler.gain = 3.5", rt.cmd("arflex:set sample-scaler gain 3.5"));
            assertEquals("3.5", rt.cmd("arflex:get sample-scaler gain"));
            assertDataFlows(rt, 3.5);
            assertTrue(rt.cmd("arflex:set sample-scaler gain 11").startsWith("error: gain: 11 is out of range"));
        }
    }

    @Test
    void providerFirstThenConsumerBothActive() throws Exception {
        try (Runtime rt = new Runtime("provider-first")) {
            rt.installAndStart(COUNTER);
            rt.awaitState("ACTIVE", T, "sample-counter");
            rt.installAndStart(SCALER);
            rt.awaitState("ACTIVE", T, "sample-counter", "sample-scaler");
            assertDataFlows(rt, 2.0);
        }
    }

    @Test
    void uninstallProviderConsumerGoesSafeAndComesBackByItself() throws Exception {
        try (Runtime rt = new Runtime("uninstall-provider")) {
            long counter = rt.installAndStart(COUNTER);
            rt.installAndStart(SCALER);
            rt.awaitState("ACTIVE", T, "sample-counter", "sample-scaler");
            assertDataFlows(rt, 2.0);
            assertEquals("", rt.cmd("uninstall " + counter));
            rt.awaitState("UNSATISFIED", T, "sample-scaler");
            assertEquals(0L, ((Number) rt.instance("sample-scaler").get("pid")).longValue());
            // safe="zero": the scaler published 0 when its input went away, before it stopped
            Ports.Sample y = Ports.readState(rt.segment("sample-scaler", "y"));
            assertNotNull(y);
            assertEquals(0.0, y.value(), "the safe output of sample-scaler");
            rt.installAndStart(COUNTER);
            rt.awaitState("ACTIVE", T, "sample-counter", "sample-scaler");
            assertDataFlows(rt, 2.0);
        }
    }

    @Test
    void killedProviderIsRestartedAndDependentsFollow() throws Exception {
        try (Runtime rt = new Runtime("kill-provider")) {
            rt.installAndStart(COUNTER);
            rt.installAndStart(SCALER);
            rt.awaitState("ACTIVE", T, "sample-counter", "sample-scaler");
            long counterPid = rt.pid("sample-counter");
            long scalerPid = rt.pid("sample-scaler");
            ProcessHandle.of(counterPid).orElseThrow().destroyForcibly(); // SIGKILL
            rt.waitUntil("a new sample-counter and sample-scaler", T, () -> {
                Map<String, Object> c = rt.instance("sample-counter");
                Map<String, Object> s = rt.instance("sample-scaler");
                return "ACTIVE".equals(c.get("state")) && "ACTIVE".equals(s.get("state"))
                        && ((Number) c.get("pid")).longValue() != counterPid
                        && ((Number) s.get("pid")).longValue() != scalerPid;
            });
            assertEquals(1L, ((Number) rt.instance("sample-counter").get("restarts")).longValue());
            assertTrue(ProcessHandle.of(counterPid).isEmpty() || !ProcessHandle.of(counterPid).get().isAlive());
            assertDataFlows(rt, 2.0);
        }
    }

    @Test
    void crashLoopEndsInFailedAndResetRevives() throws Exception {
        try (Runtime rt = new Runtime("crash-loop")) {
            rt.installAndStart(COUNTER);
            rt.installAndStart(SCALER);
            rt.awaitState("ACTIVE", T, "sample-counter", "sample-scaler");
            // intensity 3 in 10 s: the 4th crash inside the window is one too many
            for (int k = 0; k < 4; k++) {
                long pid = rt.pid("sample-counter");
                ProcessHandle ph = ProcessHandle.of(pid).orElseThrow(
                        () -> new AssertionError("pid " + pid + " of ACTIVE sample-counter is gone\n" + rt.tail()));
                ph.destroyForcibly();
                if (k < 3) {
                    rt.waitUntil("sample-counter back after crash " + (k + 1), T, () -> rt.activeWithNewPid("sample-counter", pid));
                }
            }
            rt.awaitState("FAILED", T, "sample-counter");
            String why = (String) rt.instance("sample-counter").get("failureReason");
            assertTrue(why.contains("restart intensity exceeded"), why);
            rt.awaitState("UNSATISFIED", T, "sample-scaler");
            assertTrue(rt.cmd("arflex:reset sample-counter").contains("reset"));
            rt.awaitState("ACTIVE", T, "sample-counter", "sample-scaler");
        }
    }

    @Test
    void shrinkingMemoryStopsLowestCriticalityFirstAsPlanned() throws Exception {
        try (Runtime rt = new Runtime("shrink")) {
            rt.installAndStart(COUNTER);
            rt.installAndStart(SCALER);
            rt.awaitState("ACTIVE", T, "sample-counter", "sample-scaler");
            // 8 MiB each: 12 MiB holds only one, and sample-scaler has the lower criticality
            String plan = rt.cmd("arflex:plan memory 12m");
            assertTrue(plan.lines().anyMatch(l -> l.contains("STOP") && l.contains("sample-scaler")), plan);
            assertTrue(plan.lines().noneMatch(l -> l.contains("STOP") && l.contains("sample-counter")), plan);
            long counterPid = rt.pid("sample-counter");
            rt.cmd("arflex:resources set memory 12m");
            rt.awaitState("UNSATISFIED", T, "sample-scaler");
            assertEquals("ACTIVE", rt.state("sample-counter"));
            assertEquals(counterPid, rt.pid("sample-counter"), "the plan did not restart sample-counter");
            String why = (String) rt.instance("sample-scaler").get("failureReason");
            assertTrue(why.toLowerCase().contains("memory"), why);
            rt.cmd("arflex:resources set memory 1g");
            rt.awaitState("ACTIVE", T, "sample-scaler");
        }
    }

    @Test
    void admissionRefusesWhatDoesNotFitWithTheReason() throws Exception {
        try (Runtime rt = new Runtime("refuse")) {
            rt.cmd("arflex:resources set memory 4m");
            rt.installAndStart(COUNTER);
            rt.awaitState("UNSATISFIED", T, "sample-counter");
            String why = (String) rt.instance("sample-counter").get("failureReason");
            assertTrue(why.toLowerCase().contains("memory"), why);
            assertEquals(0L, rt.pid("sample-counter"));
            assertTrue(Runtime.rtProcesses(rt.rid).isEmpty());
        }
    }

    @Test
    void badContractIsReportedAndDisturbsNothing() throws Exception {
        Path bad = Jars.withContract(SCALER, Files.createTempDirectory("arflex-it").resolve("bad.jar"),
                xml -> xml.replace("<criticality>3</criticality>", "<criticality>high</criticality>"));
        try (Runtime rt = new Runtime("bad-contract")) {
            rt.installAndStart(COUNTER);
            rt.awaitState("ACTIVE", T, "sample-counter");
            long pid = rt.pid("sample-counter");
            rt.installAndStart(bad);
            rt.waitUntil("the problem to be reported", T, () -> ((List<?>) rt.dto().get("problems")).size() > 0);
            String problems = rt.dto().get("problems").toString();
            assertTrue(problems.contains("sample-scaler.xml:"), problems);
            assertTrue(problems.contains("criticality"), problems);
            assertEquals(null, rt.instance("sample-scaler"));
            assertEquals(pid, rt.pid("sample-counter"));
            assertEquals("ACTIVE", rt.state("sample-counter"));
        }
    }

    @Test
    void restartedInstanceHasANewPid() throws Exception {
        try (Runtime rt = new Runtime("stop-start")) {
            long id = rt.installAndStart(COUNTER);
            rt.awaitState("ACTIVE", T, "sample-counter");
            long pid = rt.pid("sample-counter");
            assertEquals("", rt.cmd("stop " + id));
            rt.awaitState("INSTALLED", T, "sample-counter");
            assertEquals(0L, rt.pid("sample-counter"));
            assertTrue(Runtime.rtProcesses(rt.rid).isEmpty());
            // the output segment goes once the actor has recorded the stop (Felix's stop returns
            // when the consumers are safe, a moment before)
            rt.waitUntil("the segments removed", T, () -> rt.shmObjects().isEmpty());
            assertEquals("", rt.cmd("start " + id));
            rt.awaitState("ACTIVE", T, "sample-counter");
            assertNotEquals(pid, rt.pid("sample-counter"));
        }
    }
}
