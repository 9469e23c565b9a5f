package org.arflex.drcr.impl.runtime;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.util.List;
import java.util.concurrent.CompletableFuture;
import java.util.concurrent.CountDownLatch;
import java.util.concurrent.TimeUnit;
import org.arflex.drcr.impl.lifecycle.ManualActor;
import org.arflex.drcr.impl.lifecycle.State;
import org.arflex.drcr.impl.supervisor.RtHalf;
import org.arflex.drcr.impl.supervisor.RtLauncher;
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

    private final FakeLauncher fake = new FakeLauncher();
    private final CountDownLatch ready = new CountDownLatch(1);
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
    private final SteppedCell rig = new SteppedCell(fake, launcher, true);
    private final ManualActor actor = rig.actor;
    private final Cell cell = rig.cell;
    private final List<String> log = rig.log;

    @AfterEach
    void nothingLeaks() {
        ready.countDown();
        rig.close();
    }

    @Test
    void aHalfSlowToGetReadyHoldsNobodyAndStartsWithTheWiringAndParametersOfTheMomentItIsReady() throws Exception {
        rig.install("fast", PORTS_B);
        // fast's launch thread reports its READY through the actor: not always before install returns
        rig.stepUntil("fast ACTIVE", () -> rig.state("fast") == State.ACTIVE);
        rig.install("slow", PORTS_A);
        // slow is being launched: the actor is free, slow is not ACTIVE yet and says why
        assertEquals(State.ACTIVE, rig.state("fast"));
        assertFalse(rig.state("slow") == State.ACTIVE);
        assertEquals("starting: spawned, waiting for READY", cell.instance("slow").orElseThrow().life.reason());
        // meanwhile: a consumer of slow is installed, a parameter of slow is written, and fast
        // crashes and is restarted, all handled by the actor while slow's launch still blocks
        rig.install("user", CONSUMER);
        assertEquals("3", actor.call(() -> cell.setParam("slow", "gain", "3"), 0).replace(".0", ""));
        long fastPid = fake.running.get("fast").pid;
        fake.running.get("fast").crash(137, "killed by signal 9");
        actor.runAll();
        assertEquals(State.UNSATISFIED, rig.state("fast"));
        actor.advance(100); // its restart backoff
        rig.stepUntil("fast restarted", () -> fake.running.containsKey("fast") && fake.running.get("fast").pid != fastPid
                && rig.state("fast") == State.ACTIVE);
        assertEquals(1, ready.getCount(), "all of it happened while slow's launch blocked");

        ready.countDown();
        rig.stepUntil("slow ACTIVE", () -> rig.state("slow") == State.ACTIVE);
        FakeLauncher.FakeHalf slow = fake.running.get("slow");
        assertEquals(3.0, Double.longBitsToDouble(slow.paramValue(0)), "the parameter written while it started");
        rig.stepUntil("user bound to slow", () -> rig.state("user") == State.ACTIVE
                && fake.events.contains("user BIND x /arflex.t.slow.out.y"));
        assertNull(cell.instance("slow").orElseThrow().life.reason());
    }

    @Test
    void aStartNobodyWantsWhenItsHalfIsReadyIsStoppedAndItsNameIsFreeAgain() throws Exception {
        rig.install("slow", PORTS_A);
        // uninstalled while its half is launched: the actor does not wait for the launch
        CompletableFuture<Void> gone = actor.call(() -> cell.uninstall("slow", "bundle of slow stopped"), 0);
        actor.runAll();
        assertTrue(cell.instance("slow").isEmpty());
        // installed again at once: its start waits for the first launch to end and be stopped
        rig.install("slow", PORTS_A);
        assertEquals(1, ready.getCount());
        ready.countDown();
        rig.stepUntil("the unwanted half stopped and the new one ACTIVE", () -> gone.isDone()
                && cell.instance("slow").map(i -> i.life.state() == State.ACTIVE).orElse(false));
        long launched = fake.events.stream().filter(e -> e.equals("slow LAUNCH")).count();
        assertEquals(2, launched, fake.events.toString());
        assertTrue(log.stream().anyMatch(l -> l.contains("slow (pid") && l.contains("stopped")), log::toString);
        assertEquals(1, fake.running.size());
    }
}
