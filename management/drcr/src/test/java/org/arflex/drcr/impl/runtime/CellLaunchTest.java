package org.arflex.drcr.impl.runtime;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
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
import org.arflex.drcr.impl.supervisor.RtHalf;
import org.arflex.drcr.impl.supervisor.RtLauncher;
import org.arflex.planner.Capacities;
import org.arflex.planner.Planner;
import org.junit.jupiter.api.AfterEach;
import org.junit.jupiter.api.Test;

/**
 * Issue 17: spawning an RT half and waiting for its READY run on a launch thread, so a half that
 * takes long to get ready (a simulator loading its model, a frozen one until its READY timeout)
 * holds neither the actor nor anybody else's crash handling; a start that is no longer wanted
 * when its half is ready is stopped, and parameters written meanwhile are applied. The launch
 * and stop threads are real here; the actor is the steppable one.
 */
class CellLaunchTest {

    private static final String PORTS_A = CellTest.PROVIDER_PORTS;
    private static final String PORTS_B = CellTest.PROVIDER_PORTS.replace("\"y\"", "\"w\"");
    private static final String CONSUMER = "<in name=\"x\" type=\"arflex.Sample\" typeVersion=\"1.0\" method=\"state\">"
            + "<bind component=\"slow\" port=\"y\"/></in>";

    private final ManualActor actor = new ManualActor();
    private final FakeLauncher fake = new FakeLauncher();
    private final CountDownLatch ready = new CountDownLatch(1);
    private final List<String> log = java.util.Collections.synchronizedList(new ArrayList<>());
    private final ExecutorService stopper = Executors.newCachedThreadPool();
    private final ExecutorService launches = Executors.newCachedThreadPool();
    /** "slow" gets ready only when the test counts {@link #ready} down. */
    private final RtLauncher launcher = new RtLauncher() {
        @Override
        public RtHalf launch(Spec spec) throws IOException {
            if (spec.instance().equals("slow")) {
                try {
                    assertTrue(ready.await(10, TimeUnit.SECONDS), "never released");
                } catch (InterruptedException e) {
                    Thread.currentThread().interrupt();
                    throw new IOException("interrupted");
                }
            }
            return fake.launch(spec);
        }

        @Override
        public Output createOutput(String segmentName, int method, String typeName, int major, int minor,
                                   int elemSize, int depth, int overflow) throws IOException {
            return fake.createOutput(segmentName, method, typeName, major, minor, elemSize, depth, overflow);
        }
    };
    private final Cell cell = new Cell(new Cell.Config("t", 1000, 1000, true, PortTypes.builtin(), () -> 1_000_000_000L),
            actor, launcher, new Planner(Capacities.of(2, 1.0, 1L << 30, 1_000_000_000L)), log::add, stopper, launches);

    private void install(String name, String ports) throws Exception {
        Contract c = ContractParser.create(PortTypes.builtin()).parse(
                CellTest.contract(name, ports, CellTest.PERMANENT, false, 5, "50us"), "test.xml");
        assertTrue(actor.call(() -> cell.install(c, name.hashCode(), Path.of("/nonexistent/" + name)), 0), log::toString);
        actor.runAll();
    }

    private State state(String n) {
        return cell.instance(n).orElseThrow().life.state();
    }

    /** Steps the actor until {@code done} holds (launch and stop threads report through it), with a deadline. */
    private void stepUntil(String what, BooleanSupplier done) {
        long deadline = System.nanoTime() + TimeUnit.SECONDS.toNanos(10);
        while (!done.getAsBoolean()) {
            assertTrue(System.nanoTime() - deadline < 0, "timed out waiting for " + what + "\n" + log + "\n" + fake.events);
            actor.runAll();
            LockSupport.parkNanos(1_000_000);
        }
    }

    @AfterEach
    void nothingLeaks() {
        ready.countDown();
        actor.call(() -> {
            cell.shutdownAll("test end");
            return null;
        }, 0);
        CompletableFuture<Void> all = cell.stopsDone();
        stepUntil("every launch and stop recorded", all::isDone);
        stopper.shutdownNow();
        launches.shutdownNow();
        assertTrue(fake.running.isEmpty(), "RT halves left running: " + fake.running.keySet());
        assertTrue(fake.openOutputs.isEmpty(), "segments left: " + fake.openOutputs);
    }

    @Test
    void aHalfSlowToGetReadyHoldsNobodyAndStartsWithTheWiringAndParametersOfTheMomentItIsReady() throws Exception {
        install("fast", PORTS_B);
        install("slow", PORTS_A);
        // slow is being launched: the actor is free, slow is not ACTIVE yet and says why
        assertEquals(State.ACTIVE, state("fast"));
        assertFalse(state("slow") == State.ACTIVE);
        assertEquals("starting: spawned, waiting for READY", cell.instance("slow").orElseThrow().life.reason());
        // meanwhile: a consumer of slow is installed, a parameter of slow is written, and fast
        // crashes and is restarted, all handled by the actor while slow's launch still blocks
        install("user", CONSUMER);
        assertEquals("3", actor.call(() -> cell.setParam("slow", "gain", "3"), 0).replace(".0", ""));
        long fastPid = fake.running.get("fast").pid;
        fake.running.get("fast").crash(137, "killed by signal 9");
        actor.runAll();
        assertEquals(State.UNSATISFIED, state("fast"));
        actor.advance(100); // its restart backoff
        stepUntil("fast restarted", () -> fake.running.containsKey("fast") && fake.running.get("fast").pid != fastPid
                && state("fast") == State.ACTIVE);
        assertEquals(1, ready.getCount(), "all of it happened while slow's launch blocked");

        ready.countDown();
        stepUntil("slow ACTIVE", () -> state("slow") == State.ACTIVE);
        FakeLauncher.FakeHalf slow = fake.running.get("slow");
        assertEquals(3.0, Double.longBitsToDouble(slow.paramValue(0)), "the parameter written while it started");
        stepUntil("user bound to slow", () -> state("user") == State.ACTIVE
                && fake.events.contains("user BIND x /arflex.t.slow.out.y"));
        assertNull(cell.instance("slow").orElseThrow().life.reason());
    }

    @Test
    void aStartNobodyWantsWhenItsHalfIsReadyIsStoppedAndItsNameIsFreeAgain() throws Exception {
        install("slow", PORTS_A);
        // uninstalled while its half is launched: the actor does not wait for the launch
        CompletableFuture<Void> gone = actor.call(() -> cell.uninstall("slow", "bundle of slow stopped"), 0);
        actor.runAll();
        assertTrue(cell.instance("slow").isEmpty());
        // installed again at once: its start waits for the first launch to end and be stopped
        install("slow", PORTS_A);
        assertEquals(1, ready.getCount());
        ready.countDown();
        stepUntil("the unwanted half stopped and the new one ACTIVE", () -> gone.isDone()
                && cell.instance("slow").map(i -> i.life.state() == State.ACTIVE).orElse(false));
        long launched = fake.events.stream().filter(e -> e.equals("slow LAUNCH")).count();
        assertEquals(2, launched, fake.events.toString());
        assertTrue(log.stream().anyMatch(l -> l.contains("slow (pid") && l.contains("stopped")), log::toString);
        assertEquals(1, fake.running.size());
    }
}
