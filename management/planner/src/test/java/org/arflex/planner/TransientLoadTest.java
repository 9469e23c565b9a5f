package org.arflex.planner;

import static org.arflex.planner.impl.C.MIB;
import static org.arflex.planner.impl.C.MS;
import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.List;
import java.util.Locale;
import org.arflex.contract.Contract;
import org.arflex.planner.TransientLoad.Phase;
import org.arflex.planner.impl.C;
import org.junit.jupiter.api.Test;

/**
 * Admission of the transient cell of a change set's update (D51): while the update's shadow run
 * and its rollback window last, the old and the new RT half of the component both run, each with
 * its WCET at its priority; the plan shows that load beside the final one and refuses what is not
 * schedulable, naming the update, the phase, the CPU and the figures.
 */
class TransientLoadTest {

    private static final String S = "arflex.Sample";
    private static final Capacities CAPS = Capacities.of(2, 0.9, 512 * MIB, 10_000_000);

    private static Contract scaler() {
        return C.of("sample-scaler").in("x", S).out("y", S).timing(1, 1, 0.2, 80).crit(2).build();
    }

    private static Contract sampler(String version, double wcetMs) {
        return C.of("sampler").version(version).out("out", S).timing(1, 1, wcetMs, 90).mem(64 * MIB).crit(3).build();
    }

    private static Planner cell(double samplerWcetMs) {
        Planner p = new Planner(CAPS);
        p.apply(Change.install(scaler()));
        p.apply(Change.install(sampler("1.0.0", samplerWcetMs)));
        return p;
    }

    private static List<String> lines(List<CpuLoad> loads) {
        return loads.stream().map(l -> String.format(Locale.ROOT, "cpu %d U=%.2f/%.2f %s %s", l.cpu(), l.utilisation(),
                l.utilisationCap(), l.test(), l.tasks())).toList();
    }

    private static Change update(Contract c, long shadow, long window) {
        return Change.builder().replace(c).overlap(c.name(), shadow, window).build();
    }

    @Test
    void bothHalvesAreShownBesideTheFinalLoadOfTheirCpu() {
        Planner p = cell(0.3);
        Plan plan = p.plan(update(sampler("1.0.1", 0.3), 200, 1000));
        assertEquals("""
                plan: update sampler 1.0.0 -> 1.0.1
                actions:
                  RESTART  sampler  replaced 1.0.0 -> 1.0.1
                stop order: sampler
                start order: sampler
                wiring:
                  sample-scaler.x <- sampler.out
                cpus:
                  cpu 0  U=0.30/0.90  hyperbolic bound  sampler
                    shadow (200 cycles)  U=0.60/0.90  hyperbolic bound  sampler, sampler (new)
                    window (1000 cycles)  U=0.60/0.90  hyperbolic bound  sampler, sampler (old)
                  cpu 1  U=0.20/0.90  hyperbolic bound  sample-scaler
                memory: 65 MiB of 512 MiB; network: 0 B/s of 10 MB/s
                """, plan.toText());
        assertEquals(2, plan.transients().size());
        TransientLoad shadow = plan.transients().get(0);
        assertEquals(Phase.SHADOW, shadow.phase());
        assertEquals(200, shadow.cycles());
        assertEquals(List.of("sampler"), shadow.components());
        assertEquals(List.of("cpu 0 U=0.60/0.90 hyperbolic bound [sampler, sampler (new)]"), lines(shadow.cpus()));
        assertTrue(shadow.admitted());
        assertEquals(Phase.WINDOW, plan.transients().get(1).phase());
        assertEquals(List.of(), plan.transientRefusals());
        // the dry run and the real run plan the same, and the state keeps no overlap
        assertEquals(plan.toText(), p.apply(update(sampler("1.0.1", 0.3), 200, 1000)).toText());
        assertTrue(p.current().transients().isEmpty());
    }

    @Test
    void twoHalvesOverTheCapAreRefusedInBothPhasesThoughTheFinalCellFits() {
        Planner p = cell(0.5);
        // today's admission: the cell after the update fits (0.5 on cpu 0)
        Plan plain = p.plan(Change.replace(sampler("1.0.1", 0.5)));
        assertTrue(plain.activeAfter().contains("sampler"));
        assertTrue(plain.transients().isEmpty());
        Plan plan = p.plan(update(sampler("1.0.1", 0.5), 200, 1000));
        assertTrue(plan.activeAfter().contains("sampler"), "the final cell is admitted as before");
        assertEquals(List.of(
                "update 'sampler': its shadow run (200 cycles) runs the new half beside the old one: cpu 0: "
                        + "utilisation 1.00 with 'sampler (new)' exceeds cap 0.90",
                "update 'sampler': its rollback window (1000 cycles) keeps the old half running beside the new one: "
                        + "cpu 0: utilisation 1.00 with 'sampler (old)' exceeds cap 0.90"),
                plan.transientRefusals());
        assertFalse(plan.transients().get(0).admitted());
        assertEquals(TransientLoad.NOT_SCHEDULABLE, plan.transients().get(0).cpus().get(0).test());
        assertTrue(plan.toText().contains("""
                  cpu 0  U=0.50/0.90  hyperbolic bound  sampler
                    shadow (200 cycles)  U=1.00/0.90  not schedulable  sampler, sampler (new)
                    window (1000 cycles)  U=1.00/0.90  not schedulable  sampler, sampler (old)
                """), plan.toText());
        assertTrue(plan.toText().endsWith("""
                not schedulable while both halves run:
                  update 'sampler': its shadow run (200 cycles) runs the new half beside the old one: cpu 0: \
                utilisation 1.00 with 'sampler (new)' exceeds cap 0.90
                  update 'sampler': its rollback window (1000 cycles) keeps the old half running beside the new \
                one: cpu 0: utilisation 1.00 with 'sampler (old)' exceeds cap 0.90
                """), plan.toText());
        // no shadow run: only the window counts; no window either: nothing runs beside anything
        assertEquals(1, p.plan(update(sampler("1.0.1", 0.5), 0, 1000)).transientRefusals().size());
        assertTrue(p.plan(update(sampler("1.0.1", 0.5), 0, 0)).transients().isEmpty());
    }

    @Test
    void aSecondHalfThatMakesAnotherTaskMissItsDeadlineIsRefusedWithItsResponseTime() {
        Planner p = new Planner(Capacities.of(1, 1.0, 512 * MIB, 0));
        p.apply(Change.install(C.of("hi").timing(10, 10, 2, 3).build()));
        p.apply(Change.install(C.of("stage").timing(10, 10, 2, 2).build()));
        p.apply(Change.install(C.of("low").timing(20, 5, 1, 1).build())); // R = 1 + 2 + 2 = 5 <= 5
        Plan plan = p.plan(update(C.of("stage").version("1.1.0").timing(10, 10, 2, 2).build(), 100, 500));
        assertEquals(List.of(
                "update 'stage': its shadow run (100 cycles) runs the new half beside the old one: cpu 0: adding "
                        + "'stage (new)' gives response time 7 ms of 'low', which exceeds deadline 5 ms (U=0.65)",
                "update 'stage': its rollback window (500 cycles) keeps the old half running beside the new one: "
                        + "cpu 0: adding 'stage (old)' gives response time 7 ms of 'low', which exceeds deadline 5 ms "
                        + "(U=0.65)"),
                plan.transientRefusals());
        // the final cell is what it was
        assertEquals(List.of("cpu 0 U=0.45/1.00 response-time analysis [hi, stage, low]"),
                lines(plan.admission().cpus()));
        assertEquals(List.of("cpu 0 U=0.65/1.00 not schedulable [hi, stage, stage (new), low]"),
                lines(plan.transients().get(0).cpus()));
    }

    @Test
    void theOldHalfCountsWithItsMeasuredWcet() {
        Planner p = cell(0.3);
        p.apply(Change.measuredWcet("sampler", (long) (0.65 * MS)));
        // the new version declares 0.2 ms; admission takes the measured 0.65 ms for the component
        Plan plan = p.plan(update(sampler("1.0.1", 0.2), 0, 1000));
        assertEquals(List.of("update 'sampler': its rollback window (1000 cycles) keeps the old half running beside "
                + "the new one: cpu 0: utilisation 1.30 with 'sampler (old)' exceeds cap 0.90"),
                plan.transientRefusals());
    }

    @Test
    void eachHalfIsCountedWhereItRunsWhenTheNewVersionMoves() {
        Capacities caps = Capacities.of(2, 1.0, 512 * MIB, 0);
        Planner p = new Planner(caps);
        p.apply(Change.install(C.of("x").timing(10, 10, 4, 2, 0).crit(5).build()));
        p.apply(Change.install(C.of("other").timing(10, 10, 1, 2, 1).build()));
        p.apply(Change.install(C.of("stage").timing(10, 10, 5, 1, 0).build()));
        assertEquals(0, p.cpuAssignment().get("stage"));
        // the new version does not fit beside x any more (0.4 + 0.7): it goes to cpu 1
        Plan plan = p.plan(update(C.of("stage").version("1.1.0").timing(10, 10, 7, 1, 0, 1).build(), 100, 500));
        assertEquals(1, plan.cpuAssignment().get("stage"));
        TransientLoad shadow = plan.transients().get(0);
        TransientLoad window = plan.transients().get(1);
        // in shadow the new half runs on its planned cpu beside what runs there now
        assertEquals(List.of("cpu 1 U=0.80/1.00 hyperbolic bound [other, stage (new)]"), lines(shadow.cpus()));
        // in the window the old half stays on the cpu it was started on
        assertEquals(List.of("cpu 0 U=0.90/1.00 response-time analysis [x, stage (old)]"), lines(window.cpus()));
        assertEquals(List.of(), plan.transientRefusals());
    }

    @Test
    void serviceTasksAndComponentsThatWereNotRunningAddNothing() {
        Planner p = new Planner(CAPS);
        p.apply(Change.install(C.of("svc").service().build()));
        p.apply(Change.install(scaler())); // not running: no provider
        Plan plan = p.plan(Change.builder().replace(C.of("svc").version("1.1.0").service().build())
                .replace(C.of("sample-scaler").version("1.1.0").in("x", S).out("y", S).timing(1, 1, 0.2, 80).build())
                .overlap("svc", 100, 100).overlap("sample-scaler", 100, 100).build());
        assertTrue(plan.transients().isEmpty());
    }

    @Test
    void anOverlapOfAComponentTheChangeDoesNotReplaceIsRefusedNamingIt() {
        Planner p = cell(0.3);
        assertEquals("overlap 'sample-scaler': the change does not replace it (an overlap is the old and the new "
                + "half of an update)",
                assertThrows(IllegalArgumentException.class, () -> p.plan(Change.builder()
                        .replace(sampler("1.0.1", 0.3)).overlap("sample-scaler", 10, 10).build())).getMessage());
        assertEquals("overlap 'sampler': cycles must not be negative (shadow -1, window 0)",
                assertThrows(IllegalArgumentException.class, () -> Change.builder().overlap("sampler", -1, 0))
                        .getMessage());
    }
}
