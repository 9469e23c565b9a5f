package org.arflex.planner;

import static org.arflex.planner.impl.C.MIB;
import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertSame;

import java.util.ArrayList;
import java.util.List;
import java.util.Map;
import org.arflex.planner.impl.C;
import org.junit.jupiter.api.Test;

/** The Planner judges each CPU with the CpuAdmissionTest it was made with. */
class CpuAdmissionTestChoiceTest {

    private static final Capacities TWO_CPUS = Capacities.of(2, 0.9, 512 * MIB, 10_000_000);

    /** At most one task per CPU, whatever the load: a test no default would ever give. */
    private static final class OneTaskPerCpu implements CpuAdmissionTest {
        final List<Integer> opened = new ArrayList<>();

        @Override
        public Cpu open(int cpu) {
            opened.add(cpu);
            return new Cpu() {
                String held;

                @Override
                public String test(Task task) {
                    return held == null ? null : "'" + task.name() + "' would share with '" + held + "'";
                }

                @Override
                public Runnable add(Task task) {
                    held = task.name();
                    return () -> held = null;
                }

                @Override
                public String proof() {
                    return held == null ? "none" : "one task per cpu";
                }

                @Override
                public long responseTimeNs(String task) {
                    return 42;
                }
            };
        }
    }

    private static Change threeLightTasks() {
        return Change.builder()
                .install(C.of("a").timing(10, 10, 0.1, 30).crit(3).build())
                .install(C.of("b").timing(10, 10, 0.1, 20).crit(2).build())
                .install(C.of("c").timing(10, 10, 0.1, 10).crit(1).build())
                .build();
    }

    @Test
    void theChosenTestDecides() {
        OneTaskPerCpu test = new OneTaskPerCpu();
        Planner p = new Planner(TWO_CPUS, test);
        assertSame(test, p.cpuAdmissionTest());
        Plan plan = p.apply(threeLightTasks());
        AdmissionResult adm = plan.admission();
        assertEquals(Map.of("a", 0, "b", 1), adm.cpuAssignment());
        assertEquals("cpu 0: 'c' would share with 'a'; cpu 1: 'c' would share with 'b'", adm.refused().get("c"));
        assertEquals(List.of("one task per cpu", "one task per cpu"), adm.cpus().stream().map(CpuLoad::test).toList());
        assertEquals(42, adm.decisions().get("a").responseTimeNs());
        assertEquals("cpu 0: R=42 ns <= D=10 ms (U=0.01)", adm.decisions().get("a").reason());
        assertEquals(List.of(0, 1), test.opened.subList(0, 2));
    }

    @Test
    void theDefaultIsResponseTimeAnalysis() {
        Planner p = new Planner(TWO_CPUS);
        AdmissionResult adm = p.apply(threeLightTasks()).admission();
        assertEquals(Map.of("a", 0, "b", 1, "c", 0), adm.cpuAssignment());
        assertNull(adm.refused().get("c"));
        assertEquals("hyperbolic bound", adm.cpus().get(0).test());
        assertEquals(p.cpuAdmissionTest().getClass(), CpuAdmissionTest.responseTime().getClass());
    }
}
