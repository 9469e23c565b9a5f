package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertArrayEquals;
import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertThrows;

import java.util.ArrayList;
import java.util.List;
import org.junit.jupiter.api.Test;

/**
 * {@link SwitchWindow}: the switch turn read from the DRCR's log line, and the releases sim-robot
 * did not run around it, on states made here (1 ms releases, a seq per release run).
 */
class SwitchWindowTest {

    private static final long MS = 1_000_000L;
    private static final double[] Q = new double[6];

    /** sim-robot's states from release {@code from} to {@code to} (ms), without the releases {@code notRun}. */
    private static List<CellRig.JointState> states(long from, long to, long... notRun) {
        List<CellRig.JointState> js = new ArrayList<>();
        long seq = 100;
        for (long t = from; t <= to; t++) {
            boolean run = true;
            for (long n : notRun) {
                run &= n != t;
            }
            if (run) {
                js.add(new CellRig.JointState(t * MS, seq++, Q, Q));
            }
        }
        return js;
    }

    private static final String LINE = "arflex: change set update tcp-correction ...: switched (prepared in 41.2 ms, "
            + "switch turn 0.812 ms, monotonic 500000000..500812000 ns)";

    @Test
    void theLastSwitchTurnInTheLogIsTaken() {
        SwitchWindow w = SwitchWindow.of(List.of("arflex: something else",
                LINE.replace("500000000..500812000", "1..2"), LINE));
        assertEquals(new SwitchWindow(500_000_000L, 500_812_000L), w);
    }

    @Test
    void aLogWithoutASwitchTurnIsAFailureNamingTheLog() {
        AssertionError e = assertThrows(AssertionError.class, () -> SwitchWindow.of(List.of("arflex: rejected in shadow")));
        org.junit.jupiter.api.Assertions.assertTrue(e.getMessage().contains("rejected in shadow"), e.getMessage());
    }

    @Test
    void releasesNotRunAroundTheTurnAreCountedAndOnlyThose() {
        SwitchWindow w = SwitchWindow.of(List.of(LINE)); // 500.0 .. 500.8 ms: counted from 498 to 503.8 ms
        assertArrayEquals(new long[] {0, 7}, w.skips(states(400, 600)));
        // lost far before and after: not the switch's
        assertArrayEquals(new long[] {0, 7}, w.skips(states(400, 600, 450, 451, 560)));
        // lost in the turn, at its edges, and at the cycle boundary after it
        assertArrayEquals(new long[] {1, 6}, w.skips(states(400, 600, 500)));
        assertArrayEquals(new long[] {2, 5}, w.skips(states(400, 600, 498, 499)));
        assertArrayEquals(new long[] {1, 6}, w.skips(states(400, 600, 503)));
        // a state the recorder did not see is no release lost (its neighbours' seqs say so)
        List<CellRig.JointState> unseen = states(400, 600);
        unseen.remove(100); // the state of release 500
        assertArrayEquals(new long[] {0, 7}, w.skips(unseen));
    }

    @Test
    void theAssertionFailsOnALostReleaseAndOnARecordingThatDoesNotCoverTheTurn() {
        SwitchWindow w = SwitchWindow.of(List.of(LINE));
        w.assertNoReleaseLost("test", states(400, 600));
        AssertionError lost = assertThrows(AssertionError.class, () -> w.assertNoReleaseLost("test", states(400, 600, 501)));
        org.junit.jupiter.api.Assertions.assertTrue(lost.getMessage().contains("did not run 1 releases"), lost.getMessage());
        assertThrows(AssertionError.class, () -> w.assertNoReleaseLost("test", states(400, 502)));
        assertThrows(AssertionError.class, () -> w.assertNoReleaseLost("test", states(499, 600)));
        assertThrows(AssertionError.class, () -> w.assertNoReleaseLost("test", List.of()));
    }

    /** Releases 2000, 3000, ... 9000 not run: the machine's own single stalls, 8 in the 10 s recorded. */
    private static final long[] MACHINE = {2000, 3000, 4000, 5000, 6000, 7000, 8000, 9000};

    private static long[] with(long[] base, long... more) {
        long[] all = java.util.Arrays.copyOf(base, base.length + more.length);
        System.arraycopy(more, 0, all, base.length, more.length);
        return all;
    }

    @Test
    void aStallAroundTheTurnLikeTheMachinesOwnPassesAndOneLongerOrOneMoreFails() {
        SwitchWindow w = SwitchWindow.of(List.of(LINE)); // counted from 498 to 503.8 ms
        // 8 single stalls in ~10 s: ~0.05 expected in the turn's 5 ms; one is the machine's (p > 1e-3), two are not
        assertEquals(1, SwitchWindow.allowedStalls(w.losses(states(0, 10_000, MACHINE), false), 5));
        w.assertNoReleaseLost("test", states(0, 10_000, with(MACHINE, 501)));
        AssertionError longer = assertThrows(AssertionError.class,
                () -> w.assertNoReleaseLost("test", states(0, 10_000, with(MACHINE, 500, 501))));
        org.junit.jupiter.api.Assertions.assertTrue(longer.getMessage().contains("did not run 2 releases")
                && longer.getMessage().contains("lost 8 releases in 8 stalls (longest 1)"), longer.getMessage());
        assertThrows(AssertionError.class, () -> w.assertNoReleaseLost("test", states(0, 10_000, with(MACHINE, 499, 502))));
    }

    @Test
    void aStallAroundTheTurnFailsOnAMachineThatShowedNoneOrTooLittleToKnow() {
        SwitchWindow w = SwitchWindow.of(List.of(LINE));
        assertThrows(AssertionError.class, () -> w.assertNoReleaseLost("test", states(0, 10_000, 501)));
        // 1.5 s of baseline with stalls in it: too short to know the machine's rate
        assertEquals(0, SwitchWindow.allowedStalls(w.losses(states(0, 1_500, 100, 900, 1200), false), 5));
        assertThrows(AssertionError.class, () -> w.assertNoReleaseLost("test", states(0, 1_500, 100, 900, 1200, 501)));
    }

    @Test
    void theAllowanceGrowsWithTheMachinesRateAndTheTurnsLength() {
        SwitchWindow.Losses quiet = new SwitchWindow.Losses(12, 12, 1, 10_000); // 1.2 stalls per 1000 ms
        assertEquals(1, SwitchWindow.allowedStalls(quiet, 30)); // lambda 0.036: P(>1) 6.4e-4
        assertEquals(4, SwitchWindow.allowedStalls(new SwitchWindow.Losses(200, 200, 3, 10_000), 30)); // lambda 0.6: P(>4) 3.4e-4
        assertEquals(0, SwitchWindow.allowedStalls(new SwitchWindow.Losses(0, 0, 0, 60_000), 30));
    }
}
