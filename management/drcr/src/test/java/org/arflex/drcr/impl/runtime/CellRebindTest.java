package org.arflex.drcr.impl.runtime;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.util.List;
import java.util.concurrent.CompletableFuture;
import java.util.concurrent.CopyOnWriteArrayList;
import org.arflex.drcr.impl.lifecycle.ManualActor;
import org.arflex.drcr.impl.lifecycle.State;
import org.junit.jupiter.api.AfterEach;
import org.junit.jupiter.api.Test;

/**
 * D39, issue 17 "the actor never waits on a process": a running consumer that does not answer
 * its BIND or UNBIND at once (a frozen process, or one with a long period) does not hold the
 * actor; the plan goes on, the answer is awaited apart, the provider is stopped only once its
 * consumers' UNBINDs are answered, and a refusal restarts the consumer as before.
 */
class CellRebindTest {

    private static final String PORTS = CellTest.PROVIDER_PORTS;
    /** Optional: c keeps running without a, so losing a is a rewiring (UNBIND), not a stop. */
    private static final String CONSUMER = "<in name=\"x\" type=\"arflex.Sample\" typeVersion=\"1.0\" method=\"state\" optional=\"true\">"
            + "<bind component=\"a\" port=\"y\"/></in>";

    private final FakeLauncher launcher = new FakeLauncher();
    private final SteppedCell rig = new SteppedCell(launcher, launcher, false);
    private final ManualActor actor = rig.actor;
    private final Cell cell = rig.cell;
    /** The answers the consumer owes, in the order asked. */
    private final List<CompletableFuture<Void>> owed = new CopyOnWriteArrayList<>();

    @AfterEach
    void nothingLeaks() {
        owed.forEach(f -> f.complete(null));
        rig.close();
    }

    private void consumerAnswersLate(String name) {
        launcher.running.get(name).rebinds = what -> {
            CompletableFuture<Void> f = new CompletableFuture<>();
            owed.add(f);
            return f;
        };
    }

    @Test
    void anUnansweredUnbindHoldsTheProvidersStopNotTheActor() throws Exception {
        rig.install("a", PORTS);
        rig.install("c", CONSUMER);
        assertEquals(State.ACTIVE, rig.state("c"));
        consumerAnswersLate("c");
        CompletableFuture<Void> gone = actor.call(() -> cell.uninstall("a", "bundle a stopped"), 0);
        actor.runAll();
        // the actor went on: a is out of the cell, c runs without it, the shell answers
        assertTrue(cell.instance("a").isEmpty());
        assertEquals(State.ACTIVE, rig.state("c"));
        assertEquals("2.0", cell.getParam("c", "gain"));
        assertTrue(launcher.events.contains("c UNBIND x (unanswered)"), launcher.events.toString());
        assertTrue(rig.log.stream().anyMatch(l -> l.contains("c has not answered UNBIND x")), rig.log.toString());
        // a's stop waits for c's answer: no SHUTDOWN within a while (a bounded look, not a
        // sleep for a result: without the wait the stop thread shuts a down at once)
        long until = System.nanoTime() + 300_000_000L;
        while (System.nanoTime() < until) {
            assertFalse(launcher.events.contains("a SHUTDOWN"), "a stopped before c answered its UNBIND: " + launcher.events);
            Thread.onSpinWait();
        }
        launcher.events.add("c answers UNBIND x");
        owed.get(0).complete(null);
        rig.stepUntil("a shut down", () -> launcher.events.contains("a SHUTDOWN"));
        assertTrue(launcher.events.indexOf("c answers UNBIND x") < launcher.events.indexOf("a SHUTDOWN"), launcher.events.toString());
        rig.stepUntil("the uninstall settled", gone::isDone);
    }

    @Test
    void anUnansweredBindLetsThePlanGoOnAndARefusalRestartsTheConsumer() throws Exception {
        rig.install("a", PORTS);
        rig.install("c", CONSUMER);
        long cPid = launcher.running.get("c").pid;
        consumerAnswersLate("c");
        // a is restarted (a crash): c is rebound to the new a when it is ACTIVE again
        launcher.running.get("a").crash(137, "killed by signal 9");
        actor.runAll();
        actor.advance(100);
        rig.stepUntil("a ACTIVE again", () -> rig.state("a") == State.ACTIVE);
        rig.stepUntil("c asked to bind", () -> launcher.events.contains("c BIND x (unanswered)"));
        // the actor is free meanwhile: a parameter write is answered
        assertEquals("2.0", cell.getParam("a", "gain"));
        assertEquals(State.ACTIVE, rig.state("c"));
        // c refuses (or never answers within the call timeout): restarted as a crash would be
        owed.get(owed.size() - 1).completeExceptionally(new IOException("BIND c.x: no reply within 2000 ms"));
        rig.stepUntil("c restarted", () -> {
            actor.runAll();
            actor.advance(100);
            return launcher.running.containsKey("c") && launcher.running.get("c").pid != cPid && rig.state("c") == State.ACTIVE;
        });
        assertTrue(rig.log.stream().anyMatch(l -> l.contains("c: rewiring failed: BIND c.x: no reply within 2000 ms; restarting it")),
                rig.log.toString());
    }
}
