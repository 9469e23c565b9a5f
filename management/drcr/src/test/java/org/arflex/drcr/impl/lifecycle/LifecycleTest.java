package org.arflex.drcr.impl.lifecycle;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.ArrayList;
import java.util.List;
import java.util.concurrent.CountDownLatch;
import java.util.concurrent.TimeUnit;
import java.util.concurrent.atomic.AtomicReference;
import org.junit.jupiter.api.Test;

class LifecycleTest {

    private final ManualActor actor = new ManualActor();
    private final List<String> log = new ArrayList<>();

    @Test
    void normalPathInstalledUnsatisfiedActiveDestroyed() {
        Lifecycle l = new Lifecycle("a", actor, log::add);
        actor.onActor(() -> {
            assertEquals(State.INSTALLED, l.state());
            assertTrue(l.to(State.UNSATISFIED, "input x unbound"));
            assertEquals("input x unbound", l.reason());
            assertTrue(l.to(State.ACTIVE, null));
            assertTrue(l.to(State.UNSATISFIED, "provider lost"));
            assertTrue(l.to(State.ACTIVE, null));
            assertTrue(l.to(State.DESTROYED, "bundle stopped"));
        });
        assertTrue(log.isEmpty(), log.toString());
    }

    @Test
    void refusedTransitionIsLoggedWithReasonAndChangesNothing() {
        Lifecycle l = new Lifecycle("a", actor, log::add);
        actor.onActor(() -> {
            assertFalse(l.to(State.ACTIVE, "skip resolve"));
            assertEquals(State.INSTALLED, l.state());
            l.to(State.DESTROYED, "gone");
            assertFalse(l.to(State.UNSATISFIED, "revive"));
            assertEquals(State.DESTROYED, l.state());
        });
        assertEquals(2, log.size());
        assertTrue(log.get(0).contains("refused transition INSTALLED -> ACTIVE (skip resolve)"), log.get(0));
        assertTrue(log.get(1).contains("DESTROYED -> UNSATISFIED"), log.get(1));
    }

    @Test
    void failedLeavesOnlyByResetOrRemoval() {
        for (State s : State.values()) {
            assertEquals(s == State.UNSATISFIED || s == State.DESTROYED, Transitions.allowed(State.FAILED, s), s.name());
        }
        assertTrue(Transitions.from(State.DESTROYED).isEmpty());
    }

    @Test
    void changesOutsideTheActorThreadAreRejected() {
        Lifecycle l = new Lifecycle("a", actor, log::add);
        assertThrows(IllegalStateException.class, () -> l.to(State.UNSATISFIED, "x"));
        assertEquals(State.INSTALLED, l.state());
    }

    @Test
    void threadActorRunsOnNamedThreadInOrder() throws Exception {
        ThreadActor real = new ThreadActor(log::add);
        try {
            AtomicReference<String> name = new AtomicReference<>();
            List<Integer> order = new ArrayList<>();
            CountDownLatch done = new CountDownLatch(1);
            for (int i = 0; i < 5; i++) {
                int k = i;
                real.submit(() -> order.add(k));
            }
            real.submit(() -> {
                name.set(Thread.currentThread().getName());
                done.countDown();
            });
            assertTrue(done.await(10, TimeUnit.SECONDS));
            assertEquals(Actor.THREAD_NAME, name.get());
            assertEquals(List.of(0, 1, 2, 3, 4), order);
            assertEquals(Boolean.TRUE, real.call(real::inActor, 10_000));
        } finally {
            real.shutdown(5_000);
        }
    }

    @Test
    void manualActorFiresTimersInDueOrder() {
        List<String> fired = new ArrayList<>();
        actor.schedule(() -> fired.add("b"), 200);
        actor.schedule(() -> fired.add("a"), 100);
        Actor.Cancellable c = actor.schedule(() -> fired.add("never"), 150);
        c.cancel();
        actor.advance(99);
        assertTrue(fired.isEmpty());
        actor.advance(101);
        assertEquals(List.of("a", "b"), fired);
    }
}
