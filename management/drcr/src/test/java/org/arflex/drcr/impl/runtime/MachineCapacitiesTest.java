package org.arflex.drcr.impl.runtime;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.file.Path;
import java.util.ArrayList;
import java.util.Collections;
import java.util.List;
import java.util.Set;
import java.util.TreeSet;
import java.util.concurrent.ExecutorService;
import java.util.concurrent.Executors;
import org.arflex.contract.Contract;
import org.arflex.contract.ContractParser;
import org.arflex.contract.PortTypes;
import org.arflex.drcr.dto.ResourcesDTO;
import org.arflex.drcr.impl.lifecycle.ThreadActor;
import org.arflex.drcr.impl.machine.MachineView;
import org.arflex.drcr.impl.services.ResourceManagerImpl;
import org.arflex.drcr.impl.services.Services;
import org.arflex.planner.Capacities;
import org.arflex.planner.Planner;
import org.junit.jupiter.api.AfterEach;
import org.junit.jupiter.api.Test;

/**
 * The Resource Manager keeps the capacities within what the machine gives (D85): a CPU the
 * machine takes re-plans the cell as an API change does, the cause in the shed component's
 * reason; what the API asks beyond the machine is refused, naming it.
 */
class MachineCapacitiesTest {

    private static final String GROUP = "/arflex-it (cgroup v1)";
    private static final String LEFT = "cpu 1 left the runtime's cpuset " + GROUP;

    private final List<String> log = Collections.synchronizedList(new ArrayList<>());
    private final ThreadActor actor = new ThreadActor(log::add);
    private final ExecutorService stopper = Executors.newCachedThreadPool();
    private final ExecutorService launches = Executors.newCachedThreadPool();
    private final MachineView two = view(Set.of(0, 1), -1);
    private final Cell cell;
    private final ResourceManagerImpl rm;
    private final Services services;

    MachineCapacitiesTest() {
        ResourceManagerImpl start = new ResourceManagerImpl(null, 1.0, Set.of(), null, 1L << 30, two);
        Capacities caps = start.effective(List.of(0, 1, 2, 3), 1L << 30, 1_000_000L);
        cell = new Cell(new Cell.Config("t", 1000, 1000, true, PortTypes.builtin(), System::nanoTime), actor,
                new FakeLauncher(), new Planner(caps), log::add, stopper, launches);
        rm = new ResourceManagerImpl(cell, 1.0, Set.of(), null, 1L << 30, two);
        services = new Services(cell, rm, null, null, null, log::add);
    }

    private static MachineView view(Set<Integer> cpuset, long limit) {
        return new MachineView(new TreeSet<>(Set.of(0, 1)), new TreeSet<>(cpuset), GROUP, limit, "/job (cgroup v1)");
    }

    @AfterEach
    void stop() {
        actor.shutdown(5_000);
        stopper.shutdownNow();
        launches.shutdownNow();
    }

    private void install(String name, int criticality) throws Exception {
        Contract c = ContractParser.create(PortTypes.builtin()).parse(
                CellTest.contract(name, CellTest.PROVIDER_PORTS, CellTest.PERMANENT, false, criticality, "600us"), name + ".xml");
        assertTrue(actor.call(() -> cell.install(c, name.hashCode(), Path.of("/nonexistent/" + name)), 5_000), log::toString);
    }

    private static List<Integer> cpus(ResourcesDTO r) {
        List<Integer> l = new ArrayList<>();
        for (int c : r.cpus) {
            l.add(c);
        }
        return l;
    }

    @Test
    void theCapacitiesFollowTheMachineAndTheShedComponentNamesTheCause() throws Exception {
        assertEquals(List.of(0, 1), cpus(rm.resources()), "the machine's cpus, not the 4 of the fallback");
        install("a", 5);
        install("b", 3);
        assertEquals(Set.of("a", "b"), actor.call(() -> cell.planner().active(), 5_000));
        rm.machine(view(Set.of(0), -1), LEFT);
        assertEquals(List.of(0), cpus(rm.resources()));
        assertEquals(Set.of("a"), actor.call(() -> cell.planner().active(), 5_000));
        String why = services.instance("b").orElseThrow().failureReason;
        assertTrue(why.startsWith("cpu 0: utilisation 1.20 with 'b' exceeds cap 1.00"), why);
        assertTrue(why.endsWith("; " + LEFT), why);
        assertTrue(log.stream().anyMatch(l -> l.contains("because " + LEFT)), log::toString);
        assertEquals(LEFT, rm.resources().machineChange);
        rm.machine(two, "cpu 1 joined the runtime's cpuset " + GROUP);
        assertEquals(List.of(0, 1), cpus(rm.resources()));
        assertEquals(Set.of("a", "b"), actor.call(() -> cell.planner().active(), 5_000));
    }

    @Test
    void theApiCannotAskForMoreThanTheMachineGivesAndWhatItAsksIsKeptAcrossChanges() {
        IllegalArgumentException e = assertThrows(IllegalArgumentException.class, () -> rm.setCpus(List.of(0, 2)));
        assertEquals("cpus 2 not available to the runtime: cpus 0-1 (online 0-1, cpuset " + GROUP
                + ": 0-1), memory limit none (memory /job (cgroup v1))", e.getMessage());
        rm.setCpus(List.of(1));
        rm.machine(view(Set.of(0), -1), LEFT);
        assertEquals(List.of(), cpus(rm.resources()), "cpu 1 asked for, and the machine took it");
        rm.machine(two, "cpu 1 joined");
        assertEquals(List.of(1), cpus(rm.resources()), "what was asked for, not every cpu the machine gives");
    }

    @Test
    void aLoweredMemoryLimitLowersTheMemoryCapacityAndTheApiStaysBelowIt() {
        rm.machine(view(Set.of(0, 1), 256L << 20), "memory limit of /job (cgroup v1) set to 256 MiB");
        assertEquals(256L << 20, rm.resources().memoryBytes);
        IllegalArgumentException e = assertThrows(IllegalArgumentException.class, () -> rm.setMemory(512L << 20));
        assertTrue(e.getMessage().startsWith("memory 536870912 bytes is above the runtime's memory limit: "), e.getMessage());
        rm.machine(two, "memory limit of /job (cgroup v1) removed (was 256 MiB)");
        assertEquals(1L << 30, rm.resources().memoryBytes, "back to what was asked");
    }
}
