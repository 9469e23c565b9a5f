package org.arflex.planner.impl;

import static org.arflex.planner.impl.C.MIB;
import static org.arflex.planner.impl.C.MS;
import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.List;
import java.util.Map;
import java.util.OptionalInt;
import java.util.Set;
import org.arflex.contract.Contract;
import org.junit.jupiter.api.Test;
import org.arflex.planner.AdmissionResult;
import org.arflex.planner.Capacities;
import org.arflex.planner.Decision;

class AdmissionTest {

    private static final Capacities ONE_CPU = Capacities.of(1, 1.0, 512 * MIB, 5_000_000);

    private static AdmissionResult admit(Capacities caps, Contract... cs) {
        Resolver r = new Resolver();
        for (Contract c : cs) {
            r.put(c);
        }
        return Admission.admit(r, caps, Map.of());
    }

    @Test
    void buttazzoSetIsAdmittedByResponseTimeAnalysis() {
        AdmissionResult a = admit(ONE_CPU,
                C.of("t1").timing(4, 4, 1, 3).build(),
                C.of("t2").timing(6, 6, 2, 2).build(),
                C.of("t3").timing(10, 10, 3, 1).build());
        assertEquals(Set.of("t1", "t2", "t3"), a.admitted());
        assertEquals("response-time analysis", a.cpus().get(0).test());
        assertEquals(List.of("t1", "t2", "t3"), a.cpus().get(0).tasks());
        Decision d = a.decisions().get("t3");
        assertEquals(10 * MS, d.responseTimeNs());
        assertEquals("cpu 0: R=10 ms <= D=10 ms (U=0.88)", d.reason());
        assertEquals(3 * MS, a.decisions().get("t2").responseTimeNs());
    }

    @Test
    void lowUtilisationIsAdmittedByTheBound() {
        AdmissionResult a = admit(ONE_CPU,
                C.of("a").timing(10, 10, 2, 2).build(),
                C.of("b").timing(20, 20, 4, 1).build());
        assertEquals("hyperbolic bound", a.cpus().get(0).test());
        assertEquals("cpu 0: hyperbolic bound holds (U=0.40)", a.decisions().get("b").reason());
        assertEquals(-1, a.decisions().get("b").responseTimeNs());
    }

    @Test
    void responseTimeMissIsExplainedWithNumbers() {
        AdmissionResult a = admit(ONE_CPU,
                C.of("t1").timing(4, 4, 1, 3).build(),
                C.of("t2").timing(6, 6, 2, 2).build(),
                C.of("t3").timing(10, 10, 4, 1).build());
        assertEquals(Set.of("t1", "t2"), a.admitted());
        assertEquals("cpu 0: response time 11 ms of 't3' exceeds deadline 10 ms (U=0.98)", a.refused().get("t3"));
    }

    @Test
    void aNewUrgentTaskThatBreaksAnotherIsRefusedNamingBoth() {
        // Admitted by name: a3 (low priority) first, then z1 (high priority) would break it.
        AdmissionResult a = admit(ONE_CPU,
                C.of("a3").timing(10, 10, 4, 1).build(),
                C.of("b2").timing(6, 6, 2, 2).build(),
                C.of("z1").timing(4, 4, 1, 3).build());
        assertEquals(Set.of("a3", "b2"), a.admitted());
        assertEquals("cpu 0: adding 'z1' gives response time 11 ms of 'a3', which exceeds deadline 10 ms (U=0.98)",
                a.refused().get("z1"));
    }

    @Test
    void utilisationCap() {
        AdmissionResult a = admit(Capacities.of(1, 0.9, 512 * MIB, 0),
                C.of("a").timing(10, 10, 5, 2).build(),
                C.of("b").timing(10, 10, 5, 1).build());
        assertEquals("cpu 0: utilisation 1.00 with 'b' exceeds cap 0.90", a.refused().get("b"));
    }

    @Test
    void memoryAndNetworkBudgets() {
        AdmissionResult a = admit(ONE_CPU,
                C.of("big").mem(900 * MIB).build(),
                C.of("chatty").net(12_000_000).build(),
                C.of("small").mem(100 * MIB).net(1_000_000).build());
        assertEquals("memory: 900 MiB requested, 512 MiB free", a.refused().get("big"));
        assertEquals("network: 12 MB/s requested, 5 MB/s free", a.refused().get("chatty"));
        assertEquals(Set.of("small"), a.admitted());
        assertEquals(100 * MIB, a.memoryUsedBytes());
        assertEquals(1_000_000, a.networkUsedBps());
    }

    @Test
    void measuredWcetOverridesWhenLarger() {
        Resolver r = new Resolver();
        r.put(C.of("a").timing(10, 10, 1, 2).build());
        r.put(C.of("b").timing(10, 10, 1, 1).build());
        AdmissionResult res = Admission.admit(r, ONE_CPU, Map.of("a", 3 * MS, "b", MS / 2));
        assertEquals(3 * MS, res.decisions().get("a").wcetNs());
        assertEquals(MS, res.decisions().get("b").wcetNs());
        assertEquals("cpu 0: hyperbolic bound holds (U=0.40); measured WCET 3 ms > declared 1 ms",
                res.decisions().get("a").reason());
        res = Admission.admit(r, ONE_CPU, Map.of("a", 12 * MS));
        assertEquals("timing: WCET 12 ms exceeds deadline 10 ms (measured WCET 12 ms > declared 1 ms)",
                res.refused().get("a"));
    }

    @Test
    void worstFitAndAllowedCpus() {
        Capacities two = Capacities.of(2, 0.9, 512 * MIB, 0);
        AdmissionResult a = admit(two,
                C.of("a").timing(10, 10, 3, 5).build(),
                C.of("b").timing(10, 10, 2, 5).build(),
                C.of("c").timing(10, 10, 1, 5).build(),
                C.of("d").timing(10, 10, 1, 5, 0).build(),
                C.of("e").timing(10, 10, 1, 5, 5, 7).build());
        assertEquals(Map.of("a", 0, "b", 1, "c", 1, "d", 0), a.cpuAssignment());
        assertEquals("cpu: allowed cpus 5, 7 not in capacities (have 0, 1)", a.refused().get("e"));
    }

    @Test
    void aRunningComponentKeepsItsCpu() {
        Resolver r = new Resolver();
        r.put(C.of("a").timing(10, 10, 3, 5).build());
        r.put(C.of("b").timing(10, 10, 1, 5).build());
        AdmissionResult res = Admission.admit(List.of(r.contract("a").get(), r.contract("b").get()), r.wires(),
                Capacities.of(2, 1.0, MIB * 10, 0), Map.of(), Map.of("b", 0));
        assertEquals(Map.of("a", 1, "b", 0), res.cpuAssignment());
    }

    @Test
    void lowestCriticalityIsRefusedFirst() {
        AdmissionResult a = admit(ONE_CPU,
                C.of("a-low").timing(10, 10, 6, 1).crit(1).build(),
                C.of("b-high").timing(10, 10, 6, 2).crit(5).build());
        assertEquals(Set.of("b-high"), a.admitted());
        assertTrue(a.refused().get("a-low").startsWith("cpu 0: utilisation 1.20 with 'a-low'"), a.refused().toString());
    }

    @Test
    void refusedProviderTakesItsDependentsDown() {
        AdmissionResult a = admit(ONE_CPU,
                C.of("other").timing(10, 10, 6, 3).crit(3).build(),
                C.of("p").out("o", "arflex.Sample").timing(10, 10, 6, 2).crit(1).build(),
                C.of("c").in("x", "arflex.Sample").timing(10, 10, 1, 1).crit(1).build());
        assertEquals(Set.of("other"), a.admitted());
        assertEquals("input 'x' of 'c': provider 'p' was refused admission", a.refused().get("c"));
    }

    @Test
    void aProviderInheritsTheCriticalityOfItsDependents() {
        AdmissionResult a = admit(ONE_CPU,
                C.of("m").timing(10, 10, 5, 3).crit(3).build(),
                C.of("p").out("o", "arflex.Sample").timing(10, 10, 5, 2).crit(1).build(),
                C.of("c").in("x", "arflex.Sample").timing(10, 10, 4, 1).crit(5).build());
        assertEquals(Set.of("c", "p"), a.admitted());
        assertTrue(a.refused().get("m").startsWith("cpu 0: utilisation 1.40 with 'm'"), a.refused().toString());
    }

    @Test
    void aCycleIsAdmittedOrRefusedAsAWhole() {
        AdmissionResult a = admit(ONE_CPU,
                C.of("a").in("x", "t.B").out("y", "t.A").timing(10, 10, 3, 2).build(),
                C.of("b").in("x", "t.A").out("y", "t.B").mem(600 * MIB).build());
        assertEquals(Set.of(), a.admitted());
        assertEquals("memory: 600 MiB requested, 511 MiB free", a.refused().get("b"));
        assertEquals("refused with its cycle [a, b]: 'b': memory: 600 MiB requested, 511 MiB free",
                a.refused().get("a"));
        assertEquals(0, a.memoryUsedBytes());
        assertEquals(0.0, a.cpus().get(0).utilisation(), 1e-12);
    }

    @Test
    void serviceTasksTakeNoCpu() {
        AdmissionResult a = admit(Capacities.of(0, 1.0, 512 * MIB, 0), C.of("web").service().build());
        Decision d = a.decisions().get("web");
        assertTrue(d.admitted());
        assertEquals(OptionalInt.empty(), d.cpu());
        assertEquals("service task: no CPU budget", d.reason());
        AdmissionResult b = admit(Capacities.of(0, 1.0, 512 * MIB, 0), C.of("rt").build());
        assertEquals("cpu: no cpu in capacities", b.refused().get("rt"));
    }

    @Test
    void sporadicTasksAreAnalysedWithTheirMinimumInterArrival() {
        AdmissionResult a = admit(ONE_CPU,
                C.of("t1").sporadic().timing(4, 4, 1, 3).build(),
                C.of("t2").timing(6, 6, 2, 2).build(),
                C.of("t3").timing(10, 10, 3, 1).build());
        assertEquals(10 * MS, a.decisions().get("t3").responseTimeNs());
        assertFalse(a.refused().containsKey("t1"));
    }

    @Test
    void impossibleTimingIsRefusedWithItsReason() {
        AdmissionResult a = admit(ONE_CPU, C.of("odd").timing(10, 12, 1, 5).build());
        assertEquals("timing: deadline 12 ms is not in (0, period 10 ms]", a.refused().get("odd"));
        AdmissionResult b = admit(ONE_CPU, C.of("slow").timing(10, 5, 6, 5).build());
        assertEquals("timing: WCET 6 ms exceeds deadline 5 ms", b.refused().get("slow"));
    }
}
