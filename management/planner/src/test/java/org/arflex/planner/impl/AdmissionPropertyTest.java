package org.arflex.planner.impl;

import static org.arflex.planner.impl.C.MIB;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.ArrayList;
import java.util.List;
import java.util.Map;
import java.util.Random;
import org.arflex.contract.Contract;
import org.junit.jupiter.params.ParameterizedTest;
import org.junit.jupiter.params.provider.ValueSource;
import org.arflex.planner.AdmissionResult;
import org.arflex.planner.Capacities;
import org.arflex.planner.CpuAdmissionTest.Task;

/**
 * Admission on one CPU agrees with brute-force response-time analysis: what it admits is
 * schedulable, and every task it refuses for CPU reasons would make the admitted set
 * unschedulable (or exceed the cap). Guards the shortcuts (bound, processor demand, cached
 * response times, undo).
 */
class AdmissionPropertyTest {

    @ParameterizedTest
    @ValueSource(longs = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20})
    void agreesWithBruteForce(long seed) {
        Random rnd = new Random(seed);
        int n = 3 + rnd.nextInt(12);
        double cap = rnd.nextBoolean() ? 1.0 : 0.9;
        Resolver r = new Resolver();
        List<Contract> all = new ArrayList<>();
        long[] periods = {2, 3, 4, 5, 6, 8, 10, 12, 15, 20};
        for (int i = 0; i < n; i++) {
            long t = periods[rnd.nextInt(periods.length)];
            long d = rnd.nextInt(3) == 0 ? Math.max(1, t - rnd.nextInt((int) t)) : t;
            long c = 1 + rnd.nextInt((int) Math.max(1, d / 2));
            int prio = rnd.nextBoolean() ? (int) (100 - t) : 1 + rnd.nextInt(20);
            Contract k = C.of("t" + i).timing(t, d, c, prio).crit(1 + rnd.nextInt(3)).build();
            all.add(k);
            r.put(k);
        }
        AdmissionResult a = Admission.admit(r, Capacities.of(1, cap, 512 * MIB, 0), Map.of());
        List<Task> admitted = new ArrayList<>();
        for (Contract k : all) {
            if (a.admitted().contains(k.name())) {
                admitted.add(task(k));
            }
        }
        assertTrue(Schedulability.rtaTest(admitted), "seed " + seed + ": admitted set not schedulable " + a);
        assertTrue(Schedulability.utilisation(admitted) <= cap + 1e-9);
        for (Contract k : all) {
            if (!a.admitted().contains(k.name())) {
                List<Task> with = new ArrayList<>(admitted);
                with.add(task(k));
                boolean fits = Schedulability.rtaTest(with) && Schedulability.utilisation(with) <= cap + 1e-9;
                assertFalse(fits, "seed " + seed + ": '" + k.name() + "' was refused but fits: "
                        + a.refused().get(k.name()));
            }
        }
    }

    private static Task task(Contract k) {
        return new Task(k.name(), k.timing().periodNs(), k.timing().deadlineNs(), k.timing().wcetNs(),
                k.timing().priority());
    }
}
