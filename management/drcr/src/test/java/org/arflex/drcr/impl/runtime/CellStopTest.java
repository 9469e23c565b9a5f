package org.arflex.drcr.impl.runtime;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.concurrent.CompletableFuture;
import java.util.concurrent.CountDownLatch;
import java.util.concurrent.ExecutorService;
import java.util.concurrent.Executors;
import java.util.concurrent.TimeUnit;
import java.util.concurrent.locks.LockSupport;
import java.util.function.BooleanSupplier;
import org.arflex.contract.Contract;
import org.arflex.contract.ContractParser;
import org.arflex.contract.PortTypes;
import org.arflex.drcr.impl.lifecycle.ManualActor;
import org.arflex.drcr.impl.lifecycle.State;
import org.arflex.planner.Capacities;
import org.arflex.planner.Planner;
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

    private final ManualActor actor = new ManualActor();
    private final FakeLauncher launcher = new FakeLauncher();
    private final List<String> log = java.util.Collections.synchronizedList(new ArrayList<>());
    private final ExecutorService stopper = Executors.newCachedThreadPool();
    private final Cell cell = new Cell(new Cell.Config("t", 1000, 1000, true, PortTypes.builtin(), () -> 1_000_000_000L),
            actor, launcher, new Planner(Capacities.of(2, 1.0, 1L << 30, 1_000_000_000L)), log::add, stopper, Runnable::run);
    private final CountDownLatch release = new CountDownLatch(1);

    private void install(String name, String ports) throws Exception {
        Contract c = ContractParser.create(PortTypes.builtin()).parse(
                CellTest.contract(name, ports, PERMANENT, false, 5, "50us"), "test.xml");
        assertTrue(actor.call(() -> cell.install(c, name.hashCode(), Path.of("/nonexistent/" + name)), 0), log::toString);
        actor.runAll();
    }

    private State state(String n) {
        return cell.instance(n).orElseThrow().life.state();
    }

    /** Steps the actor until {@code done} holds (a stop thread reports through the actor), with a deadline. */
    private void stepUntil(String what, BooleanSupplier done) {
        long deadline = System.nanoTime() + TimeUnit.SECONDS.toNanos(10);
        while (!done.getAsBoolean()) {
            assertTrue(System.nanoTime() - deadline < 0, "timed out waiting for " + what + "\n" + log + "\n" + launcher.events);
            actor.runAll();
            LockSupport.parkNanos(1_000_000);
        }
    }

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
        actor.call(() -> {
            cell.shutdownAll("test end");
            return null;
        }, 0);
        CompletableFuture<Void> all = cell.stopsDone();
        stepUntil("every stop recorded", all::isDone);
        stopper.shutdownNow();
        assertTrue(launcher.running.isEmpty(), "RT halves left running: " + launcher.running.keySet());
        assertTrue(launcher.openOutputs.isEmpty(), "segments left: " + launcher.openOutputs);
    }

    @Test
    void aHalfWhoseStopBlocksDoesNotBlockTheActorAnotherCrashIsHandledMeanwhile() throws Exception {
        install("a", A_PORTS);
        install("b", B_PORTS);
        install("c", A_CONSUMER);
        assertEquals(State.ACTIVE, state("c"));
        Instance a = cell.instance("a").orElseThrow();
        FakeLauncher.FakeHalf oldA = launcher.running.get("a");
        long aPid = oldA.pid;
        freeze("a");
        CompletableFuture<Void> settled = actor.call(() -> cell.uninstall("a", "bundle a stopped"), 0);
        actor.runAll();
        // the actor returned at once: the consumer is down (UNBIND came first), a is gone from
        // the cell, its stop is in progress on the stop thread, its segment still there
        assertTrue(cell.instance("a").isEmpty());
        assertEquals(State.UNSATISFIED, state("c"));
        stepUntil("a's stop under way", () -> launcher.events.contains("a SHUTDOWN"));
        stepUntil("the caller told a did not answer", settled::isDone);
        assertTrue(launcher.events.indexOf("c UNBIND x") < launcher.events.indexOf("a SHUTDOWN"), launcher.events.toString());
        assertEquals(1, launcher.openOutputs.getOrDefault("/arflex.t.a.out.y", 0), "a's segment outlives a");
        assertFalse(a.life.state() == State.DESTROYED, "DESTROYED only once its process is gone");

        // Meanwhile another component crashes: handled at once, and restarted after its backoff.
        long bPid = launcher.running.get("b").pid;
        launcher.running.get("b").crash(137, "killed by signal 9");
        actor.runAll();
        assertTrue(log.stream().anyMatch(l -> l.contains("b (pid " + bPid + ") killed by signal 9")), log.toString());
        assertEquals(State.UNSATISFIED, state("b"));
        actor.advance(100);
        assertEquals(State.ACTIVE, state("b"), log.toString());
        // and the shell is answered: a command on the actor returns
        assertEquals("2.0", cell.getParam("b", "gain"));

        // a reinstalled while its old half is still on its way out: the new one waits for it
        install("a", A_PORTS);
        assertEquals(State.UNSATISFIED, state("a"));
        assertTrue(cell.instance("a").orElseThrow().life.reason().contains("previous RT half"),
                cell.instance("a").orElseThrow().life.reason());
        assertTrue(launcher.running.get("a") == oldA, "only the old half of a, still on its way out");
        assertEquals(1, launcher.events.stream().filter(e -> e.equals("a LAUNCH")).count(), launcher.events.toString());

        release.countDown();
        stepUntil("the new a running", () -> state("a") == State.ACTIVE);
        assertTrue(launcher.running.get("a") != oldA);
        assertEquals(State.DESTROYED, a.life.state());
        assertTrue(a.life.reason().contains("bundle a stopped") && a.life.reason().contains("killed after"),
                a.life.reason());
        assertTrue(log.stream().anyMatch(l -> l.contains("a (pid " + aPid + ") stopped:") && l.contains("killed after")),
                log.toString());
        // the old segment was closed before the new one was made: one open, made twice
        assertEquals(1, launcher.openOutputs.get("/arflex.t.a.out.y"));
        stepUntil("c bound and running again", () -> state("c") == State.ACTIVE);
        assertTrue(launcher.events.lastIndexOf("a START") < launcher.events.lastIndexOf("c START"), launcher.events.toString());
    }
}
