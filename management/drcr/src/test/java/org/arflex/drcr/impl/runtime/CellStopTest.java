package org.arflex.drcr.impl.runtime;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.List;
import java.util.concurrent.CompletableFuture;
import java.util.concurrent.CountDownLatch;
import java.util.concurrent.TimeUnit;
import org.arflex.drcr.impl.lifecycle.ManualActor;
import org.arflex.drcr.impl.lifecycle.State;
import org.junit.jupiter.api.AfterEach;
import org.junit.jupiter.api.Test;

/**
 * Issue 17 finding 1: stops run on a stop thread, so a half whose stop blocks (a frozen
 * process) does not block the actor. The stop thread is real here; the actor is the steppable
 * one.
 */
class CellStopTest {

    private static final String PERMANENT = CellTest.PERMANENT;
    private static final String A_PORTS = CellTest.PROVIDER_PORTS;
    private static final String B_PORTS = CellTest.PROVIDER_PORTS.replace("\"y\"", "\"w\"");
    private static final String A_CONSUMER = "<in name=\"x\" type=\"arflex.Sample\" typeVersion=\"1.0\" method=\"state\">"
            + "<bind component=\"a\" port=\"y\"/></in>";

    private final FakeLauncher launcher = new FakeLauncher();
    private final SteppedCell rig = new SteppedCell(launcher, launcher, false);
    private final ManualActor actor = rig.actor;
    private final Cell cell = rig.cell;
    private final List<String> log = rig.log;
    private final CountDownLatch release = new CountDownLatch(1);

    /** A frozen process: its stop blocks until the test releases it, then it is killed. */
    private void freeze(String name) {
        FakeLauncher.FakeHalf h = launcher.running.get(name);
        h.answers = false;
        h.untilKilled = () -> {
            try {
                assertTrue(release.await(10, TimeUnit.SECONDS), "never released");
            } catch (InterruptedException e) {
                Thread.currentThread().interrupt();
            }
        };
    }

    @AfterEach
    void nothingLeaks() {
        release.countDown();
        rig.close();
    }

    @Test
    void aHalfWhoseStopBlocksDoesNotBlockTheActorAnotherCrashIsHandledMeanwhile() throws Exception {
        rig.install("a", A_PORTS);
        rig.install("b", B_PORTS);
        rig.install("c", A_CONSUMER);
        assertEquals(State.ACTIVE, rig.state("c"));
        Instance a = cell.instance("a").orElseThrow();
        FakeLauncher.FakeHalf oldA = launcher.running.get("a");
        long aPid = oldA.pid;
        freeze("a");
        CompletableFuture<Void> settled = actor.call(() -> cell.uninstall("a", "bundle a stopped"), 0);
        actor.runAll();
        // the actor returned at once: the consumer is down (UNBIND came first), a is gone from
        // the cell, its stop is in progress on the stop thread, its segment still there
        assertTrue(cell.instance("a").isEmpty());
        assertEquals(State.UNSATISFIED, rig.state("c"));
        rig.stepUntil("a's stop under way", () -> launcher.events.contains("a SHUTDOWN"));
        rig.stepUntil("the caller told a did not answer", settled::isDone);
        assertTrue(launcher.events.indexOf("c UNBIND x") < launcher.events.indexOf("a SHUTDOWN"), launcher.events.toString());
        assertEquals(1, launcher.openOutputs.getOrDefault("/arflex.t.a.out.y", 0), "a's segment outlives a");
        assertFalse(a.life.state() == State.DESTROYED, "DESTROYED only once its process is gone");

        // Meanwhile another component crashes: handled at once, and restarted after its backoff.
        long bPid = launcher.running.get("b").pid;
        launcher.running.get("b").crash(137, "killed by signal 9");
        // seen where the exit completes (the JDK's reaper thread), before the actor's turn
        assertTrue(log.stream().anyMatch(l -> l.contains("b (pid " + bPid + ") exit seen: killed by signal 9")), log.toString());
        assertFalse(log.stream().anyMatch(l -> l.contains("b (pid " + bPid + ") killed by signal 9")), log.toString());
        actor.runAll();
        assertTrue(log.stream().anyMatch(l -> l.contains("b (pid " + bPid + ") killed by signal 9 (handled ")), log.toString());
        assertEquals(State.UNSATISFIED, rig.state("b"));
        actor.advance(100);
        assertEquals(State.ACTIVE, rig.state("b"), log.toString());
        // and the shell is answered: a command on the actor returns
        assertEquals("2.0", cell.getParam("b", "gain"));

        // a reinstalled while its old half is still on its way out: the new one waits for it
        rig.install("a", A_PORTS);
        assertEquals(State.UNSATISFIED, rig.state("a"));
        assertTrue(cell.instance("a").orElseThrow().life.reason().contains("previous RT half"),
                cell.instance("a").orElseThrow().life.reason());
        assertTrue(launcher.running.get("a") == oldA, "only the old half of a, still on its way out");
        assertEquals(1, launcher.events.stream().filter(e -> e.equals("a LAUNCH")).count(), launcher.events.toString());

        release.countDown();
        rig.stepUntil("the new a running", () -> rig.state("a") == State.ACTIVE);
        assertTrue(launcher.running.get("a") != oldA);
        assertEquals(State.DESTROYED, a.life.state());
        assertTrue(a.life.reason().contains("bundle a stopped") && a.life.reason().contains("killed after"),
                a.life.reason());
        assertTrue(log.stream().anyMatch(l -> l.contains("a (pid " + aPid + ") stopped:") && l.contains("killed after")),
                log.toString());
        // the old segment was closed before the new one was made: one open, made twice
        assertEquals(1, launcher.openOutputs.get("/arflex.t.a.out.y"));
        rig.stepUntil("c bound and running again", () -> rig.state("c") == State.ACTIVE);
        assertTrue(launcher.events.lastIndexOf("a START") < launcher.events.lastIndexOf("c START"), launcher.events.toString());
    }
}
