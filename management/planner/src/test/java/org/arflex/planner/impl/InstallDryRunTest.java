package org.arflex.planner.impl;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.ArrayList;
import java.util.List;
import java.util.Optional;
import java.util.Random;
import org.arflex.contract.Binding;
import org.arflex.contract.Contract;
import org.arflex.contract.PortSpec.Method;
import org.arflex.planner.Capacities;
import org.arflex.planner.Change;
import org.arflex.planner.CpuAdmissionTest;
import org.arflex.planner.Plan;
import org.junit.jupiter.api.Test;

/**
 * The plan of one install derived from the plan of no change ({@link InstallDryRun}) equals the
 * full computation, field by field, on seeded random cells: missing and refused providers,
 * cycles, optional inputs, service tasks, blocked components, measured WCETs, constrained
 * deadlines (response-time analysis), allowed and exclusive CPUs, CPUs and budgets too small
 * (refusals). An engine that always plans in full is the reference; the same changes go to
 * both. The dry run leaves the state as it was, and applying the install gives the same plan
 * and state too.
 */
class InstallDryRunTest {

    private static final String[] TYPES = {"t.A", "t.B", "t.C"};
    private static final long MS = 1_000_000L;
    private static final long[] PERIODS = {1 * MS, 2 * MS, 5 * MS, 10 * MS, 20 * MS};

    /** What the cases covered (the derivation must really be exercised). */
    private static final class Tally {
        int cases;
        int dryRuns;
        int derived;
        int derivedRefused;
        int derivedUnsatisfied;
        int derivedStarted;
    }

    @Test
    void derivedPlansEqualFullPlansOnRandomCells() {
        Tally tally = new Tally();
        for (long seed = 1; seed <= 300; seed++) {
            runCase(seed, tally, CpuAdmissionTest.responseTime());
        }
        assertEquals(300, tally.cases);
        String t = "dry runs " + tally.dryRuns + ", derived " + tally.derived + " (started " + tally.derivedStarted
                + ", refused " + tally.derivedRefused + ", unsatisfied " + tally.derivedUnsatisfied + ")";
        assertTrue(tally.derived * 3 > tally.dryRuns, t);
        assertTrue(tally.derivedStarted > 100, t);
        assertTrue(tally.derivedRefused > 20, t);
        assertTrue(tally.derivedUnsatisfied > 20, t);
        assertTrue(tally.derived < tally.dryRuns, "the fallback must be exercised too: " + t);
    }

    /** Another schedulability test: at most three tasks per CPU, response time = own WCET. */
    private static final class AtMostThree implements CpuAdmissionTest {
        @Override
        public Cpu open(int cpu) {
            return new Cpu() {
                final List<String> held = new ArrayList<>();

                @Override
                public String test(Task task) {
                    return held.size() < 3 ? null : "'" + task.name() + "' would be the fourth after " + held;
                }

                @Override
                public Runnable add(Task task) {
                    held.add(task.name());
                    return () -> held.remove(task.name());
                }

                @Override
                public String proof() {
                    return held.isEmpty() ? "none" : held.size() + " of 3";
                }

                @Override
                public long responseTimeNs(String task) {
                    return held.indexOf(task) * 1000L;
                }
            };
        }
    }

    @Test
    void derivedPlansUseTheChosenTest() {
        Tally tally = new Tally();
        for (long seed = 1001; seed <= 1080; seed++) {
            runCase(seed, tally, new AtMostThree());
        }
        assertTrue(tally.derivedStarted > 10 && tally.derivedRefused > 5, tally.derivedStarted + " " + tally.derivedRefused);
    }

    private static void runCase(long seed, Tally tally, CpuAdmissionTest test) {
        Random rnd = new Random(seed);
        int n = 3 + rnd.nextInt(seed % 25 == 0 ? 120 : 30);
        int cpus = 1 + rnd.nextInt(4);
        Capacities caps = Capacities.of(cpus, 0.5 + rnd.nextInt(5) / 10.0, (long) (n / 2 + rnd.nextInt(n * 2 + 1)) << 20,
                rnd.nextInt(4) == 0 ? 5_000 : 1_000_000);
        PlanEngine full = new PlanEngine(caps, test, false);
        PlanEngine inc = new PlanEngine(caps, test, true);
        String ctx = "seed " + seed;
        // Build the cell: a batch, then a few one by one (installs that may be derived themselves).
        List<Contract> first = new ArrayList<>();
        int batch = Math.max(0, n - rnd.nextInt(4));
        for (int i = 0; i < batch; i++) {
            first.add(member(rnd, "c" + i, n));
        }
        both(full, inc, Change.install(first.toArray(new Contract[0])), ctx + " batch");
        for (int i = batch; i < n; i++) {
            both(full, inc, Change.install(member(rnd, "c" + i, n)), ctx + " c" + i);
        }
        if (rnd.nextInt(4) == 0) {
            both(full, inc, Change.block("c" + rnd.nextInt(n), "failed: exit 3"), ctx + " block");
        }
        if (rnd.nextInt(4) == 0) {
            both(full, inc, Change.measuredWcet("c" + rnd.nextInt(n), (1 + rnd.nextInt(3)) * MS), ctx + " measured");
        }
        // Dry runs of one install, then one of them applied, then dry runs again.
        for (int round = 0; round < 2; round++) {
            List<Contract> xs = new ArrayList<>();
            for (int k = 0; k < 4; k++) {
                xs.add(newcomer(rnd, "x" + round + k, n));
            }
            for (Contract x : xs) {
                String c = ctx + " round " + round + " dry run " + x.name();
                String before = snapshot(inc);
                long d0 = inc.derivedPlans();
                Change ch = Change.install(x);
                Plan expected = full.plan(ch);
                Plan actual = inc.plan(ch);
                assertSame(expected, actual, c);
                assertEquals(before, snapshot(inc), c + ": the dry run changed the state");
                tally.dryRuns++;
                if (inc.derivedPlans() > d0) {
                    tally.derived++;
                    if (!actual.starts().isEmpty()) {
                        tally.derivedStarted++;
                    } else if (actual.admission().decisions().containsKey(x.name())) {
                        tally.derivedRefused++;
                    } else {
                        tally.derivedUnsatisfied++;
                    }
                }
            }
            both(full, inc, Change.install(xs.get(rnd.nextInt(xs.size()))), ctx + " round " + round + " apply");
        }
        tally.cases++;
    }

    /** Applies the change to both engines; the plans and the states must be the same. */
    private static void both(PlanEngine full, PlanEngine inc, Change change, String ctx) {
        Plan expected = full.apply(change);
        Plan actual = inc.apply(change);
        assertSame(expected, actual, ctx);
        assertEquals(snapshot(full), snapshot(inc), ctx);
    }

    static void assertSame(Plan e, Plan a, String ctx) {
        assertEquals(e.toText(), a.toText(), ctx);
        assertEquals(e.title(), a.title(), ctx);
        assertEquals(e.actions(), a.actions(), ctx);
        assertEquals(e.stopOrder(), a.stopOrder(), ctx);
        assertEquals(e.startGroups(), a.startGroups(), ctx);
        assertEquals(e.activeBefore(), a.activeBefore(), ctx);
        assertEquals(e.activeAfter(), a.activeAfter(), ctx);
        assertEquals(e.inactiveAfter(), a.inactiveAfter(), ctx);
        assertEquals(e.wiring(), a.wiring(), ctx);
        assertEquals(e.admission(), a.admission(), ctx);
        assertEquals(e.cycles(), a.cycles(), ctx);
        assertEquals(e.notes(), a.notes(), ctx);
        assertEquals(e.change(), a.change(), ctx);
    }

    /** Everything the engine answers about its state. */
    static String snapshot(PlanEngine p) {
        StringBuilder sb = new StringBuilder();
        sb.append(p.contracts()).append('\n').append(p.active()).append('\n').append(p.blocked()).append('\n')
                .append(p.cpuAssignment()).append('\n').append(p.measuredWcetNs()).append('\n').append(p.capacities())
                .append('\n').append(p.wires()).append('\n');
        for (Contract c : p.contracts()) {
            sb.append(p.satisfaction(c.name())).append('\n');
        }
        return sb.append(p.current().toText()).toString();
    }

    /** A member of the cell: inputs from any member (installed or not yet: cycles, missing providers). */
    private static Contract member(Random rnd, String name, int n) {
        C c = C.of(name).attr("id", name).attr("role", rnd.nextBoolean() ? "robot" : "camera");
        c.out("o", TYPES[rnd.nextInt(TYPES.length)], "1." + rnd.nextInt(2), Method.STATE);
        c.out("u", "u." + name);
        int ins = rnd.nextInt(3);
        for (int i = 0; i < ins; i++) {
            input(rnd, c, "i" + i, "c" + rnd.nextInt(n + 2));
        }
        return timed(rnd, c).build();
    }

    /** A component to install: mostly read from the cell and feed nobody; sometimes not. */
    private static Contract newcomer(Random rnd, String name, int n) {
        C c = C.of(name).attr("id", name).attr("role", "robot");
        if (rnd.nextInt(6) == 0) {
            c.out("o", TYPES[rnd.nextInt(TYPES.length)], "1.1", Method.STATE); // may be picked up
        }
        c.out("u", "u." + name);
        int ins = rnd.nextInt(3);
        for (int i = 0; i < ins; i++) {
            input(rnd, c, "i" + i, rnd.nextInt(8) == 0 ? "missing" : "c" + rnd.nextInt(n));
        }
        timed(rnd, c);
        if (rnd.nextInt(5) == 0) {
            c.timing(5, 5, 1 + rnd.nextInt(5), 1 + rnd.nextInt(90)); // heavy: often unschedulable
        }
        if (rnd.nextInt(8) == 0) {
            c.mem((long) (n + 8) << 20); // often over the memory budget
        }
        return c.build();
    }

    private static void input(Random rnd, C c, String port, String provider) {
        int k = rnd.nextInt(10);
        boolean optional = rnd.nextInt(8) == 0;
        if (k < 5) {
            c.in(port, "u." + provider, "1.0", Method.STATE, Optional.of(Binding.explicit(provider, "u")), optional);
        } else if (k < 7) {
            c.in(port, "u." + provider, "1.0", Method.STATE, Optional.of(Binding.filter("(id=" + provider + ")")), optional);
        } else if (k < 9) {
            c.in(port, "u." + provider, "1.0", Method.STATE, Optional.empty(), optional);
        } else {
            c.in(port, TYPES[rnd.nextInt(TYPES.length)], "1.0", Method.STATE, Optional.empty(), optional); // maybe ambiguous
        }
    }

    private static C timed(Random rnd, C c) {
        int kind = rnd.nextInt(10);
        if (kind < 4) {
            c.service();
        } else if (kind < 5) {
            c.sporadic();
        }
        long period = PERIODS[rnd.nextInt(PERIODS.length)];
        long deadline = rnd.nextInt(5) == 0 ? period / 2 : period;
        long wcet = Math.max(10_000, period * (1 + rnd.nextInt(25)) / 100);
        int prio = rnd.nextInt(3) == 0 ? 1 + rnd.nextInt(90) : 90 - (int) (period / MS);
        List<Integer> allowed = new ArrayList<>();
        if (rnd.nextInt(5) == 0) {
            allowed.add(rnd.nextInt(3));
        }
        c.timing(period / (double) MS, Math.min(deadline, period) / (double) MS, Math.min(wcet, deadline) / (double) MS,
                prio, allowed.toArray(new Integer[0]));
        if (rnd.nextInt(40) == 0) {
            c.exclusive();
        }
        return c.crit(rnd.nextInt(4)).mem((1L + rnd.nextInt(3)) << 20).net(rnd.nextInt(3) * 1000L);
    }
}
