package org.arflex.planner.impl;

import static org.arflex.planner.impl.C.MIB;
import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.ArrayList;
import java.util.HashMap;
import java.util.List;
import java.util.Map;
import java.util.Random;
import java.util.Set;
import org.arflex.contract.Contract;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.params.ParameterizedTest;
import org.junit.jupiter.params.provider.ValueSource;
import org.arflex.planner.AdmissionResult;
import org.arflex.planner.Capacities;
import org.arflex.planner.CpuAdmissionTest.Task;

/** Exclusive CPUs (contract, SPEC 8.6) and reserved CPUs (capacities). */
class CpuReservationTest {

    private static final Capacities TWO = Capacities.of(2, 1.0, 512 * MIB, 0);

    private static AdmissionResult admit(Capacities caps, Contract... cs) {
        Resolver r = new Resolver();
        for (Contract c : cs) {
            r.put(c);
        }
        return Admission.admit(r, caps, Map.of());
    }

    @Test
    void exclusiveTaskKeepsItsCpuAndOthersGoElsewhere() {
        AdmissionResult a = admit(TWO,
                C.of("probe").timing(1, 1, 0.02, 90, 1).crit(9).exclusive().build(),
                C.of("counter").timing(10, 10, 0.2, 50).crit(5).build(),
                C.of("scaler").timing(10, 10, 0.2, 40).crit(3).build());
        assertEquals(Set.of("probe", "counter", "scaler"), a.admitted());
        assertEquals(Map.of("probe", 1, "counter", 0, "scaler", 0), a.cpuAssignment());
        assertEquals(List.of("probe"), a.cpus().get(1).tasks());
        assertTrue(a.decisions().get("probe").reason().startsWith("cpu 1 (exclusive): "),
                a.decisions().get("probe").reason());
    }

    @Test
    void withoutExclusiveARunningTaskStaysOnTheProbesCpu() {
        // The effect the latency benchmark found: a component placed on cpu 1 while the probe
        // was absent keeps cpu 1 when the probe arrives, unless the probe is exclusive.
        for (boolean exclusive : new boolean[] {false, true}) {
            C probe = C.of("probe").timing(1, 1, 0.02, 90, 1).crit(9);
            Resolver r = new Resolver();
            r.put((exclusive ? probe.exclusive() : probe).build());
            r.put(C.of("scaler").timing(10, 10, 0.2, 40).crit(3).build());
            AdmissionResult a = Admission.admit(List.of(r.contract("probe").get(), r.contract("scaler").get()),
                    r.wires(), TWO, Map.of(), Map.of("scaler", 1), Set.of("scaler"));
            assertEquals(Map.of("probe", 1, "scaler", exclusive ? 0 : 1), a.cpuAssignment());
        }
    }

    @Test
    void aTaskThatNamesTheExclusiveCpuIsRefusedNamingTheHolder() {
        AdmissionResult a = admit(TWO,
                C.of("probe").timing(1, 1, 0.02, 90, 1).crit(9).exclusive().build(),
                C.of("pinned").timing(10, 10, 0.2, 50, 1).crit(5).build());
        assertEquals(Set.of("probe"), a.admitted());
        assertEquals("cpu 1: held exclusively by 'probe' (timing/@exclusive)", a.refused().get("pinned"));
    }

    @Test
    void exclusiveTaskOfHigherCriticalityPushesSharedTasksOffItsCpu() {
        // 'pinned-elsewhere' may use either CPU but the probe wants cpu 1: it goes to 0.
        Resolver r = new Resolver();
        r.put(C.of("probe").timing(1, 1, 0.02, 90, 1).crit(9).exclusive().build());
        r.put(C.of("shared").timing(10, 10, 0.2, 50).crit(5).build());
        AdmissionResult a = Admission.admit(List.of(r.contract("probe").get(), r.contract("shared").get()),
                r.wires(), TWO, Map.of(), Map.of("shared", 1), Set.of("shared"));
        assertEquals(Map.of("probe", 1, "shared", 0), a.cpuAssignment());
    }

    @Test
    void lessCriticalExclusiveTaskIsRefusedWhenItsCpuIsTaken() {
        AdmissionResult a = admit(TWO,
                C.of("ctl").timing(1, 1, 0.1, 80, 1).crit(9).build(),
                C.of("probe").timing(1, 1, 0.02, 90, 1).crit(2).exclusive().build());
        assertEquals(Set.of("ctl"), a.admitted());
        assertEquals("cpu 1: 'probe' asks for a cpu of its own (timing/@exclusive), but cpu 1 already holds 'ctl'",
                a.refused().get("probe"));
    }

    @Test
    void sharedTasksLeaveTheCpuAnExclusiveCandidateWantsEvenWhenAdmittedFirst() {
        // 'a' is more critical and admitted first; worst fit alone would put 'b' on cpu 1 too
        // (cpu 0 holds 'a'), so the less critical exclusive probe would be refused.
        AdmissionResult a = admit(TWO,
                C.of("a").timing(10, 10, 1, 50).crit(9).build(),
                C.of("b").timing(10, 10, 1, 40).crit(8).build(),
                C.of("probe").timing(1, 1, 0.02, 90, 1).crit(1).exclusive().build());
        assertEquals(Set.of("a", "b", "probe"), a.admitted());
        assertEquals(Map.of("a", 0, "b", 0, "probe", 1), a.cpuAssignment());
    }

    @Test
    void exclusiveWithoutCpusTakesAnEmptyCpuAndIsRefusedWhenThereIsNone() {
        AdmissionResult a = admit(TWO,
                C.of("a").timing(10, 10, 1, 50, 0).crit(9).build(),
                C.of("probe").timing(1, 1, 0.02, 90).crit(5).exclusive().build(),
                C.of("z").timing(10, 10, 1, 40).crit(1).build());
        assertEquals(Map.of("a", 0, "probe", 1, "z", 0), a.cpuAssignment());

        AdmissionResult b = admit(TWO,
                C.of("a").timing(10, 10, 1, 50, 0).crit(9).build(),
                C.of("b").timing(10, 10, 1, 50, 1).crit(9).build(),
                C.of("probe").timing(1, 1, 0.02, 90).crit(5).exclusive().build());
        assertEquals("cpu 0: 'probe' asks for a cpu of its own (timing/@exclusive), but cpu 0 already holds 'a'; "
                + "cpu 1: 'probe' asks for a cpu of its own (timing/@exclusive), but cpu 1 already holds 'b'",
                b.refused().get("probe"));
    }

    @Test
    void twoExclusiveTasksCannotShare() {
        AdmissionResult a = admit(TWO,
                C.of("p1").timing(1, 1, 0.02, 90, 1).crit(9).exclusive().build(),
                C.of("p2").timing(1, 1, 0.02, 90, 1).crit(8).exclusive().build());
        assertEquals(Set.of("p1"), a.admitted());
        assertEquals("cpu 1: held exclusively by 'p1' (timing/@exclusive)", a.refused().get("p2"));
    }

    @Test
    void reservedCpuTakesOnlyTasksThatNameIt() {
        Capacities caps = TWO.withReserved(List.of(1));
        assertEquals(List.of(1), caps.reservedCpus());
        AdmissionResult a = admit(caps,
                C.of("named").timing(1, 1, 0.02, 90, 1).crit(1).build(),
                C.of("any1").timing(10, 10, 0.2, 50).crit(5).build(),
                C.of("any2").timing(10, 10, 0.2, 40).crit(5).build());
        assertEquals(Map.of("named", 1, "any1", 0, "any2", 0), a.cpuAssignment());

        AdmissionResult b = admit(Capacities.of(1, 1.0, 512 * MIB, 0).withReserved(List.of(0)),
                C.of("any").timing(10, 10, 0.2, 50).build());
        assertEquals("cpu: every capacity cpu is reserved (0) and the contract names none in timing/@cpus",
                b.refused().get("any"));
        assertFalse(TWO.cpus().get(1).reserved());
    }

    @Test
    void reservingAnUnknownCpuIsAnError() {
        IllegalArgumentException e = assertThrows(IllegalArgumentException.class, () -> TWO.withReserved(List.of(3)));
        assertEquals("reserved cpu 3 is not among the capacity cpus [0, 1]", e.getMessage());
    }

    @Test
    void refusedGroupUndoesItsExclusiveHold() {
        // 'probe' (exclusive) is admitted in a cycle with 'partner' that cannot fit: the whole
        // cycle is refused and cpu 1 must be free again for a later task that names it.
        AdmissionResult a = admit(TWO,
                C.of("probe").timing(1, 1, 0.02, 90, 1).crit(9).exclusive()
                        .out("o", "arflex.Sample").inFrom("i", "arflex.Sample", "partner", "o").build(),
                C.of("partner").timing(1, 1, 2, 80, 0).crit(9)
                        .out("o", "arflex.Sample").inFrom("i", "arflex.Sample", "probe", "o").build(),
                C.of("later").timing(10, 10, 0.2, 50, 1).crit(1).build());
        assertFalse(a.admitted().contains("probe"));
        assertEquals(Map.of("later", 1), a.cpuAssignment());
    }

    /**
     * Random sets on 4 CPUs with random exclusive tasks, pinned tasks and a reserved CPU: an
     * exclusive task never shares its CPU, no task lets admission choose a reserved CPU, every
     * task runs within its allowed CPUs, and each CPU's set stays schedulable.
     */
    @ParameterizedTest
    @ValueSource(longs = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20})
    void invariantsHoldOnRandomSets(long seed) {
        Random rnd = new Random(seed);
        Capacities caps = Capacities.of(4, 1.0, 512 * MIB, 0);
        int reserved = rnd.nextInt(5); // 4: none
        if (reserved < 4) {
            caps = caps.withReserved(List.of(reserved));
        }
        Resolver r = new Resolver();
        List<Contract> all = new ArrayList<>();
        long[] periods = {1, 2, 5, 10, 20};
        int n = 4 + rnd.nextInt(12);
        for (int i = 0; i < n; i++) {
            long t = periods[rnd.nextInt(periods.length)];
            double c = Math.max(0.01, t * rnd.nextDouble() * 0.4);
            List<Integer> cpus = new ArrayList<>();
            if (rnd.nextInt(3) == 0) {
                cpus.add(rnd.nextInt(4));
                if (rnd.nextBoolean()) {
                    int other = rnd.nextInt(4);
                    if (!cpus.contains(other)) {
                        cpus.add(other);
                    }
                }
            }
            C b = C.of("t" + i).timing(t, t, c, 1 + rnd.nextInt(90), cpus.toArray(new Integer[0]))
                    .crit(rnd.nextInt(10));
            Contract k = (rnd.nextInt(4) == 0 ? b.exclusive() : b).build();
            all.add(k);
            r.put(k);
        }
        AdmissionResult a = Admission.admit(r, caps, Map.of());
        Map<Integer, List<Contract>> on = new HashMap<>();
        for (Contract k : all) {
            if (a.cpuOf(k.name()).isPresent()) {
                int cpu = a.cpuOf(k.name()).getAsInt();
                on.computeIfAbsent(cpu, x -> new ArrayList<>()).add(k);
                if (!k.timing().cpus().isEmpty()) {
                    assertTrue(k.timing().cpus().contains(cpu), "seed " + seed + ": " + k.name() + " on " + cpu);
                } else {
                    assertFalse(caps.cpu(cpu).orElseThrow().reserved(),
                            "seed " + seed + ": " + k.name() + " let admission choose and got reserved cpu " + cpu);
                }
            }
        }
        for (var e : on.entrySet()) {
            List<Contract> ks = e.getValue();
            for (Contract k : ks) {
                if (k.timing().exclusive()) {
                    assertEquals(1, ks.size(), "seed " + seed + ": exclusive " + k.name() + " shares cpu " + e.getKey()
                            + " with " + ks.stream().map(Contract::name).toList());
                }
            }
            List<Task> tasks = new ArrayList<>();
            for (Contract k : ks) {
                tasks.add(new Task(k.name(), k.timing().periodNs(), k.timing().deadlineNs(),
                        k.timing().wcetNs(), k.timing().priority()));
            }
            assertTrue(Schedulability.rtaTest(tasks), "seed " + seed + ": cpu " + e.getKey() + " not schedulable");
        }
    }
}
