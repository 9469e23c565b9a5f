package org.arflex.drcr.impl.runtime;

import static org.arflex.drcr.impl.runtime.UpdateRig.IN_SRC;
import static org.arflex.drcr.impl.runtime.UpdateRig.OUT;
import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertNotNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.List;
import org.arflex.contract.Contract;
import org.arflex.drcr.impl.lifecycle.ManualActor;
import org.junit.jupiter.api.AfterEach;
import org.junit.jupiter.api.Test;

/**
 * A change set's update runs the old and the new RT half of a component at once: the new one in
 * its shadow run before the switch (D42), the old one for its rollback window after it (D38).
 * The DRCR asks the real planner to count both (D51): a set whose two halves do not fit on their
 * CPU is refused by its plan, naming the update, the phase, the CPU and the figures, before
 * anything is spawned; a set whose halves fit shows their load beside the final one.
 *
 * <p>The cell of {@link CellUpdateSetTest} ({@code src -> stage -> user}, 1 ms periods, the
 * test cell's two CPUs with a cap of 1.0), {@code stage} updated with its own WCET.
 */
class CellTransientAdmissionTest {

    private final UpdateRig rig = new UpdateRig();
    private final FakeLauncher fake = rig.fake;
    private final ManualActor actor = rig.actor;
    private final Cell cell = rig.cell;

    @AfterEach
    void nothingLeaks() {
        rig.close();
    }

    private static Contract parse(String name, String role, String ports, String version, String wcet) throws Exception {
        return UpdateRig.parse(name, role, ports, version, wcet, "");
    }

    /** src and user take 50 us each, stage {@code wcet}: stage has a CPU of its own (worst fit). */
    private int runningCell(String wcet) throws Exception {
        rig.runningCell(wcet, "");
        int cpu = cell.planner().cpuAssignment().get("stage");
        assertNotEquals(cell.planner().cpuAssignment().get("src"), cpu);
        assertNotEquals(cell.planner().cpuAssignment().get("user"), cpu);
        return cpu;
    }

    private static void assertNotEquals(Object a, Object b) {
        assertFalse(a.equals(b), a + " == " + b);
    }

    private ChangeSet update(String wcet, long window, long shadow) throws Exception {
        return UpdateRig.update(parse("stage", "stage", IN_SRC + OUT, "1.1.0", wcet), window, shadow, List.of());
    }

    @Test
    void anUpdateWhoseTwoHalvesDoNotFitTheirCpuIsRefusedBeforeAnythingIsSpawned() throws Exception {
        int cpu = runningCell("600us");
        int before = fake.events.size();
        ChangeSetResult dry = actor.call(() -> cell.planChangeSet(update("600us", 100, 50)), 0);
        assertFalse(dry.admitted(), dry.text());
        String shadow = "update 'stage': its shadow run (50 cycles) runs the new half beside the old one: cpu " + cpu
                + ": utilisation 1.20 with 'stage (new)' exceeds cap 1.00";
        String window = "update 'stage': its rollback window (100 cycles) keeps the old half running beside the new "
                + "one: cpu " + cpu + ": utilisation 1.20 with 'stage (old)' exceeds cap 1.00";
        assertEquals(shadow + "; " + window, dry.refusal());
        // the plan shows the final cell (admitted: 0.6 on its cpu) and both transient loads beside it
        assertTrue(dry.text().contains("  cpu " + cpu + "  U=0.60/1.00  hyperbolic bound  stage\n"
                + "    shadow (50 cycles)  U=1.20/1.00  not schedulable  stage, stage (new)\n"
                + "    window (100 cycles)  U=1.20/1.00  not schedulable  stage, stage (old)\n"), dry.text());
        // applied: refused the same, nothing spawned, bound or created, the old half runs on
        ChangeSetResult r = rig.apply(update("600us", 100, 50));
        assertFalse(r.applied(), r.text());
        assertEquals(shadow + "; " + window, r.refusal());
        assertEquals(before, fake.events.size(), fake.events::toString);
        assertFalse(fake.running.containsKey("1-stage"));
        assertTrue(fake.running.containsKey("stage"));
        assertEquals("1.0.0", cell.instance("stage").orElseThrow().contract().version().toString());
        assertEquals("1.0.0", cell.planner().contract("stage").orElseThrow().version().toString());
        // without a shadow run only the window is refused
        ChangeSetResult noShadow = actor.call(() -> cell.planChangeSet(update("600us", 100, 0)), 0);
        assertEquals(window, noShadow.refusal());
    }

    @Test
    void twoHalvesThatFitAreAdmittedAndShownBesideTheFinalLoad() throws Exception {
        int cpu = runningCell("400us");
        int before = fake.events.size();
        ChangeSetResult dry = actor.call(() -> cell.planChangeSet(update("400us", 100, 50)), 0);
        assertTrue(dry.admitted(), dry.text());
        assertTrue(dry.text().contains("  cpu " + cpu + "  U=0.40/1.00  hyperbolic bound  stage\n"
                + "    shadow (50 cycles)  U=0.80/1.00  hyperbolic bound  stage, stage (new)\n"
                + "    window (100 cycles)  U=0.80/1.00  hyperbolic bound  stage, stage (old)\n"), dry.text());
        assertFalse(dry.text().contains("not schedulable"), dry.text());
        assertEquals(before, fake.events.size(), fake.events::toString);
    }
}
