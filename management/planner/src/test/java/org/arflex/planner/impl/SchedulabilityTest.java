package org.arflex.planner.impl;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.List;
import org.junit.jupiter.api.Test;
import org.arflex.planner.CpuAdmissionTest.Task;

/** Response-time analysis and bounds against hand-computed textbook examples (units: ticks). */
class SchedulabilityTest {

    private static Task t(String n, long c, long period, int prio) {
        return new Task(n, period, period, c, prio);
    }

    @Test
    void liuLaylandBoundValues() {
        assertEquals(1.0, Schedulability.liuLaylandBound(1), 1e-12);
        assertEquals(0.828427, Schedulability.liuLaylandBound(2), 1e-6);
        assertEquals(0.779763, Schedulability.liuLaylandBound(3), 1e-6);
        assertEquals(Math.log(2), Schedulability.liuLaylandBound(100_000), 1e-5);
    }

    /**
     * Buttazzo, Hard Real-Time Computing Systems, response-time analysis example: C = 1, 2, 3;
     * T = D = 4, 6, 10, rate monotonic. U = 0.883 fails both bounds; RTA by hand:
     * R1 = 1; R2 = 2 -> 3 -> 3; R3 = 3 -> 6 -> 7 -> 9 -> 10 -> 10 <= 10.
     */
    @Test
    void buttazzoExampleFailsTheBoundsButPassesRta() {
        Task t1 = t("t1", 1, 4, 3);
        Task t2 = t("t2", 2, 6, 2);
        Task t3 = t("t3", 3, 10, 1);
        List<Task> set = List.of(t1, t2, t3);
        assertEquals(0.8833, Schedulability.utilisation(set), 1e-4);
        assertTrue(Schedulability.boundsApply(set));
        assertFalse(Schedulability.liuLaylandTest(set));
        assertFalse(Schedulability.hyperbolicTest(set));
        assertEquals(1, Schedulability.responseTime(t1, set));
        assertEquals(3, Schedulability.responseTime(t2, set));
        assertEquals(10, Schedulability.responseTime(t3, set));
        assertTrue(Schedulability.rtaTest(set));
    }

    /** Same set with C3 = 4 (U = 0.983): R3 = 4 -> 7 -> 10 -> 11 > 10, unschedulable. */
    @Test
    void oneMoreTickMissesTheDeadline() {
        Task t1 = t("t1", 1, 4, 3);
        Task t2 = t("t2", 2, 6, 2);
        Task t3 = t("t3", 4, 10, 1);
        List<Task> set = List.of(t1, t2, t3);
        assertEquals(-1, Schedulability.responseTime(t3, set));
        assertFalse(Schedulability.rtaTest(set));
    }

    /** Harmonic periods 2, 4, 8 with C = 1, 1, 2: U = 1 and still schedulable, R3 = 8. */
    @Test
    void harmonicSetAtFullUtilisation() {
        Task t1 = t("t1", 1, 2, 3);
        Task t2 = t("t2", 1, 4, 2);
        Task t3 = t("t3", 2, 8, 1);
        List<Task> set = List.of(t1, t2, t3);
        assertEquals(1.0, Schedulability.utilisation(set), 1e-12);
        assertFalse(Schedulability.hyperbolicTest(set));
        assertEquals(2, Schedulability.responseTime(t2, set));
        assertEquals(8, Schedulability.responseTime(t3, set));
    }

    /** U = (0.6, 0.25): 0.85 is above the two-task L&L bound 0.828, the product 1.6 * 1.25 = 2 is not. */
    @Test
    void hyperbolicBoundIsTighterThanLiuLayland() {
        List<Task> set = List.of(t("a", 6, 10, 2), t("b", 5, 20, 1));
        assertFalse(Schedulability.liuLaylandTest(set));
        assertTrue(Schedulability.hyperbolicTest(set));
        assertTrue(Schedulability.rtaTest(set));
    }

    @Test
    void boundsDoNotApplyToConstrainedDeadlinesOrNonRateMonotonicPriorities() {
        assertFalse(Schedulability.boundsApply(List.of(new Task("a", 10, 5, 1, 1))));
        // The longer period has the higher priority: not rate monotonic.
        List<Task> inverted = List.of(t("a", 1, 4, 1), t("b", 1, 10, 2));
        assertFalse(Schedulability.boundsApply(inverted));
        assertFalse(Schedulability.hyperbolicTest(inverted));
        // Equal periods may share or differ in priority.
        assertTrue(Schedulability.boundsApply(List.of(t("a", 1, 4, 1), t("b", 1, 4, 1), t("c", 1, 8, 0))));
        assertFalse(Schedulability.boundsApply(List.of(t("a", 1, 4, 1), t("c", 1, 8, 1))));
    }

    /**
     * Priority inversion of rate monotonic: t2 (T = 10) above t1 (T = 4). R1 = 1 + 4 = 5 > D = 4
     * although U = 0.65; with rate-monotonic priorities it passes (R2 = 4 -> 5 -> 6).
     */
    @Test
    void priorityOrderMatters() {
        Task t1 = t("t1", 1, 4, 1);
        Task t2 = t("t2", 4, 10, 2);
        assertEquals(-1, Schedulability.responseTime(t1, List.of(t1, t2)));
        Task t1hi = t("t1", 1, 4, 3);
        assertEquals(6, Schedulability.responseTime(t2, List.of(t1hi, t2))); // 4 -> 5 -> 6 -> 6
    }

    /** Equal priorities interfere both ways (FIFO order unknown): R = C1 + C2 for both. */
    @Test
    void equalPrioritiesCountAsInterference() {
        Task a = t("a", 2, 10, 5);
        Task b = t("b", 3, 10, 5);
        assertEquals(5, Schedulability.responseTime(a, List.of(a, b)));
        assertEquals(5, Schedulability.responseTime(b, List.of(a, b)));
    }

    /** Constrained deadline: T = 10, D = 4, C = 2 under a task C = 2, T = 5: R = 4 <= 4. */
    @Test
    void constrainedDeadline() {
        Task hi = t("hi", 2, 5, 2);
        Task lo = new Task("lo", 10, 4, 2, 1);
        assertEquals(4, Schedulability.responseTime(lo, List.of(hi, lo)));
        Task tight = new Task("lo", 10, 3, 2, 1);
        assertEquals(-1, Schedulability.responseTime(tight, List.of(hi, tight)));
    }

    @Test
    void startValueSpeedsUpButDoesNotChangeTheResult() {
        Task t1 = t("t1", 1, 4, 3);
        Task t2 = t("t2", 2, 6, 2);
        Task t3 = t("t3", 3, 10, 1);
        assertEquals(10, Schedulability.responseTime(t3, List.of(t1, t2, t3), 9));
    }

    @Test
    void badTasksAreRefusedWithTheirName() {
        IllegalArgumentException e = assertThrows(IllegalArgumentException.class, () -> new Task("x", 10, 11, 1, 1));
        assertEquals("task 'x': deadline 11 ns is not in (0, period 10 ns]", e.getMessage());
        assertThrows(IllegalArgumentException.class, () -> new Task("x", 0, 1, 1, 1));
        assertThrows(IllegalArgumentException.class, () -> new Task("x", 10, 10, 0, 1));
    }
}
