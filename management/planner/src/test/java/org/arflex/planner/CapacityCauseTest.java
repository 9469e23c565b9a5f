package org.arflex.planner;

import static org.arflex.planner.impl.C.MIB;
import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.List;
import java.util.Map;
import org.arflex.planner.impl.C;
import org.junit.jupiter.api.Test;

/**
 * A capacity change that the machine made (a CPU left the runtime's cpuset, a memory limit was
 * lowered) carries its cause; the plan's title and the reasons of what it stops, moves and starts
 * name it (docs/decisions/D85).
 */
class CapacityCauseTest {

    private static final String GONE = "cpu 1 left the runtime's cpuset /arflex-it (cgroup v1)";
    private static final String BACK = "cpu 1 joined the runtime's cpuset /arflex-it (cgroup v1)";

    /** a (crit 5, 5 ms of 10) and b (crit 3, 3 ms of 10) on two CPUs; m (crit 1) needs R <= 5 ms. */
    private static Planner cell() {
        Planner p = new Planner(Capacities.of(2, 1.0, 512 * MIB, 0));
        p.apply(Change.install(C.of("a").timing(10, 10, 5, 50).crit(5).build(),
                C.of("b").timing(10, 10, 3, 40).crit(3).build(),
                C.of("m").timing(20, 5, 1, 5).crit(1).build()));
        assertEquals(Map.of("a", 0, "b", 1, "m", 1), p.cpuAssignment());
        return p;
    }

    @Test
    void aCpuTakenByTheMachineShedsAndMovesWithTheCauseInEveryReason() {
        Planner p = cell();
        Plan gone = p.apply(Change.capacities(Capacities.of(1, 1.0, 512 * MIB, 0), GONE));
        assertTrue(gone.title().endsWith("because " + GONE), gone.title());
        assertEquals(new Plan.Action(Plan.Op.RESTART, "b", "moved cpu 1 -> 0; " + GONE), gone.action("b").get());
        assertEquals(Plan.Op.STOP, gone.action("m").get().op());
        String why = gone.inactiveAfter().get("m");
        assertTrue(why.startsWith("cpu 0: response time 9 ms of 'm' exceeds deadline 5 ms"), why);
        assertTrue(why.endsWith("; " + GONE), why);
        assertEquals(why, gone.action("m").get().reason());
        Plan back = p.apply(Change.capacities(Capacities.of(2, 1.0, 512 * MIB, 0), BACK));
        assertEquals(List.of("m"), back.startOrder());
        String started = back.action("m").get().reason();
        assertTrue(started.startsWith("admitted now (was refused: cpu 0: response time 9 ms"), started);
        assertTrue(started.endsWith("; " + BACK), started);
        assertTrue(back.inactiveAfter().isEmpty(), back.inactiveAfter()::toString);
    }

    @Test
    void aChangeWithoutACauseKeepsItsReasonsAsBefore() {
        Planner p = cell();
        Plan gone = p.plan(Change.capacities(Capacities.of(1, 1.0, 512 * MIB, 0)));
        assertEquals(new Plan.Action(Plan.Op.RESTART, "b", "moved cpu 1 -> 0"), gone.action("b").get());
        assertTrue(gone.inactiveAfter().get("m").endsWith("(U=0.85)"), gone.inactiveAfter().get("m"));
    }

    @Test
    void aBlankCauseIsRefused() {
        IllegalArgumentException e = assertThrows(IllegalArgumentException.class,
                () -> Change.capacities(Capacities.of(1, 1.0, 0, 0), " "));
        assertEquals("the cause of a change must not be blank", e.getMessage());
    }
}
