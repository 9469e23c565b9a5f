package org.arflex.drcr.impl.lifecycle;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.ArrayList;
import java.util.Collections;
import java.util.List;
import java.util.concurrent.CountDownLatch;
import java.util.concurrent.TimeUnit;
import java.util.concurrent.locks.LockSupport;
import org.junit.jupiter.api.AfterEach;
import org.junit.jupiter.api.Test;

/** The real actor: order, a failing task, and the log of its longest wait (issue 17's stall). */
class ThreadActorTest {

    private final List<String> log = Collections.synchronizedList(new ArrayList<>());
    private final ThreadActor actor = new ThreadActor(log::add);

    @AfterEach
    void stop() {
        actor.shutdown(5_000);
    }

    private List<String> lags() {
        synchronized (log) {
            return log.stream().filter(l -> l.contains("the actor answered after")).toList();
        }
    }

    @Test
    void runsInOrderOnItsThreadAndSurvivesAFailingTask() {
        List<Integer> seen = Collections.synchronizedList(new ArrayList<>());
        for (int i = 0; i < 100; i++) {
            int k = i;
            actor.submit(() -> seen.add(k));
        }
        actor.submit(() -> {
            throw new IllegalStateException("boom");
        });
        assertTrue(actor.call(actor::inActor, 5_000));
        assertEquals(100, seen.size());
        for (int i = 0; i < 100; i++) {
            assertEquals(i, seen.get(i));
        }
        assertTrue(log.stream().anyMatch(l -> l.contains("actor task failed") && l.contains("boom")), log::toString);
    }

    @Test
    void aTaskThatWaitedLongerThanEverIsLoggedWithItsWait() throws Exception {
        CountDownLatch blocking = new CountDownLatch(1);
        CountDownLatch release = new CountDownLatch(1);
        actor.submit(() -> {
            blocking.countDown();
            try {
                release.await(10, TimeUnit.SECONDS);
            } catch (InterruptedException e) {
                Thread.currentThread().interrupt();
            }
        });
        assertTrue(blocking.await(10, TimeUnit.SECONDS));
        actor.submit(() -> { }); // waits behind the blocking task
        long queued = System.nanoTime(); // after the actor's own stamp: its wait is at least ours
        // the wait to produce: 10 x the threshold, measured on the clock, not slept
        long produced = 10 * ThreadActor.LAG_LOG_MS;
        while (System.nanoTime() - queued < produced * 1_000_000L) {
            LockSupport.parkNanos(1_000_000);
        }
        release.countDown();
        actor.call(() -> null, 5_000);
        List<String> lags = lags();
        assertTrue(!lags.isEmpty(), log::toString);
        String last = lags.get(lags.size() - 1);
        assertTrue(Long.parseLong(last.replaceAll(".*after (\\d+) ms.*", "$1")) >= produced, last);
        // a shorter wait afterwards is not the longest yet
        actor.call(() -> null, 5_000);
        assertEquals(lags.size(), lags().size());
    }

    /** A task that holds the actor, as a stop that waits on a process would. */
    private static void holdTheActor(CountDownLatch release) {
        try {
            release.await(10, TimeUnit.SECONDS);
        } catch (InterruptedException e) {
            Thread.currentThread().interrupt();
        }
    }

    @Test
    void aTaskThatHoldsTheActorIsReportedOnceWithWhereItIs() throws Exception {
        assertEquals(null, actor.watch(50), "an idle actor: nothing to report");
        CountDownLatch running = new CountDownLatch(1);
        CountDownLatch release = new CountDownLatch(1);
        actor.submit(() -> {
            running.countDown();
            holdTheActor(release);
        });
        assertTrue(running.await(10, TimeUnit.SECONDS));
        long started = System.nanoTime();
        assertEquals(null, actor.watch(60_000), "not over the threshold");
        String frames = null;
        while (frames == null && System.nanoTime() - started < 10_000_000_000L) {
            frames = actor.watch(50);
            LockSupport.parkNanos(1_000_000);
        }
        assertTrue(frames != null && frames.contains("ThreadActorTest.holdTheActor"), String.valueOf(frames));
        assertEquals(null, actor.watch(50), "reported once per task");
        String line = log.stream().filter(l -> l.contains("an actor task has run")).findFirst().orElse("");
        assertTrue(line.contains("ThreadActorTest.holdTheActor") && Long.parseLong(line.replaceAll(".*has run (\\d+) ms.*", "$1")) >= 50,
                line);
        release.countDown();
    }
}
