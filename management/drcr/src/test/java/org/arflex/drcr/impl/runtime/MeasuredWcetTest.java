package org.arflex.drcr.impl.runtime;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertNotEquals;
import static org.junit.jupiter.api.Assertions.assertSame;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import org.arflex.contract.ContractParser;
import org.arflex.contract.PortTypes;
import org.arflex.drcr.impl.lifecycle.ManualActor;
import org.arflex.drcr.impl.lifecycle.State;
import org.arflex.planner.Capacities;
import org.arflex.planner.Planner;
import org.junit.jupiter.api.AfterEach;
import org.junit.jupiter.api.BeforeEach;
import org.junit.jupiter.api.Test;

/**
 * The measured WCET the cell re-plans with (D73's last finding, D82): taken only from executions
 * no machine stall inflated. A half of 1 ms period declared at 50 us that really runs 60 us in
 * 4 % of its cycles is re-planned at about 60 us; one stall of the machine (a 3 ms execution)
 * in the same window must not become its WCET: at 3 ms a 1 ms period is inadmissible and the
 * component would be stopped (before: "measured execution time 3000000 ns", refused).
 */
class MeasuredWcetTest {
    static final long WCET = 50_000;

    private final ManualActor actor = new ManualActor();
    private final FakeLauncher launcher = new FakeLauncher();
    private final List<String> log = new ArrayList<>();
    private final Cell cell = new Cell(new Cell.Config("t", 1000, 1000, true, PortTypes.builtin(), () -> 1_000_000_000L),
            actor, launcher, new Planner(Capacities.of(2, 1.0, 1L << 30, 1_000_000_000L)), log::add);
    private FakeLauncher.FakeHalf half;
    private final ExecHistory exec = new ExecHistory();

    @BeforeEach
    void install() throws Exception {
        var c = ContractParser.create(PortTypes.builtin())
                .parse(CellTest.contract("prov", CellTest.PROVIDER_PORTS, CellTest.PERMANENT, false, 5, "50us"), "test.xml");
        assertTrue(actor.call(() -> cell.install(c, 1, Path.of("/nonexistent/prov")), 0), log::toString);
        actor.runAll();
        half = launcher.running.get("prov");
    }

    @AfterEach
    void close() {
        actor.call(() -> {
            cell.shutdownAll("test end");
            return null;
        }, 0);
        actor.runAll();
    }

    private void window() {
        exec.into(half, WCET);
        actor.call(cell::sample, 0);
        actor.runAll();
    }

    private State state() {
        return cell.instance("prov").orElseThrow().life.state();
    }

    @Test
    void oneStallDoesNotBecomeTheMeasuredWcet() {
        exec.run(1000, 20_000);
        window();
        exec.run(960, 20_000).run(39, 60_000).run(1, 3_000_000);  // sustained at 60 us, and one stall
        window();
        exec.run(960, 20_000).run(40, 60_000);
        window();
        assertTrue(log.stream().anyMatch(l -> l.contains("measured execution time 60100 ns")), log::toString);
        assertTrue(log.stream().noneMatch(l -> l.contains("3000000 ns above")), log::toString);
        assertEquals(State.ACTIVE, state(), log::toString);
        assertSame(half, launcher.running.get("prov"), "not restarted");
    }

    @Test
    void aStallInOneWindowOfOverflowingExecutionsIsNotTheMeasuredWcet() {
        // above the histogram's 200 us only an estimate of the long executions' mean is known;
        // a window holding a stall among them is outweighed by the window after it
        exec.run(1000, 20_000);
        window();
        exec.run(960, 20_000).run(39, 250_000).run(1, 40_000_000);
        window();
        exec.run(960, 20_000).run(40, 250_000);
        window();
        assertTrue(log.stream().anyMatch(l -> l.contains("measured execution time 250000 ns")), log::toString);
        assertEquals(State.ACTIVE, state(), log::toString);
    }

    @Test
    void aSustainedExceedanceAloneInOneWindowIsNotReplannedYet() {
        exec.run(1000, 20_000);
        window();
        exec.run(960, 20_000).run(40, 60_000);
        window();
        assertTrue(log.stream().noneMatch(l -> l.contains("re-planning")), log::toString);
        exec.run(1000, 20_000);
        window();
        assertTrue(log.stream().noneMatch(l -> l.contains("re-planning")), "two windows in a row, not two at all: " + log);
    }

    @Test
    void aSustainedExceedanceTooLongForThePeriodIsStillRefused() {
        exec.run(1000, 20_000);
        window();
        exec.run(960, 20_000).run(40, 1_500_000);
        window();
        exec.run(960, 20_000).run(40, 1_500_000);
        window();
        assertTrue(log.stream().anyMatch(l -> l.contains("measured execution time 1500000 ns")), log::toString);
        assertNotEquals(State.ACTIVE, state(), log::toString);
        String reason = cell.instance("prov").orElseThrow().life.reason();
        assertTrue(reason.contains("measured WCET"), reason);
        assertFalse(launcher.running.containsKey("prov"));
    }
}
