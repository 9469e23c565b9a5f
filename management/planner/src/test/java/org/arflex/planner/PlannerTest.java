package org.arflex.planner;

import static org.arflex.planner.impl.C.MIB;
import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.List;
import java.util.Map;
import java.util.Set;
import org.arflex.contract.Contract;
import org.arflex.contract.PortSpec.Method;
import org.junit.jupiter.api.Test;
import org.arflex.planner.impl.C;

class PlannerTest {

    private static final String S = "arflex.Sample";
    private static final Capacities CAPS = Capacities.of(2, 0.9, 512 * MIB, 10_000_000);

    private static Contract scaler() {
        return C.of("sample-scaler").in("x", S).out("y", S).timing(1, 1, 0.2, 80).crit(2).build();
    }

    private static Contract sampler() {
        return C.of("sampler").out("out", S).timing(1, 1, 0.3, 90).mem(64 * MIB).crit(3).build();
    }

    private static Planner cell() {
        Planner p = new Planner(CAPS);
        p.apply(Change.install(scaler()));
        p.apply(Change.install(sampler()));
        return p;
    }

    @Test
    void installConsumerFirstThenProvider() {
        Planner p = new Planner(CAPS);
        Plan first = p.apply(Change.install(scaler()));
        assertTrue(first.isEmpty());
        assertEquals(Map.of("sample-scaler", "input 'x' of 'sample-scaler': no provider of arflex.Sample 1.x (state)"),
                first.inactiveAfter());
        Plan second = p.apply(Change.install(sampler()));
        assertEquals("""
                plan: install sampler 1.0.0
                actions:
                  START    sample-scaler  now satisfied (x <- sampler.out); cpu 1: hyperbolic bound holds (U=0.20)
                  START    sampler        installed; cpu 0: hyperbolic bound holds (U=0.30)
                stop order: (none)
                start order: sampler, sample-scaler
                wiring:
                  sample-scaler.x <- sampler.out
                cpus:
                  cpu 0  U=0.30/0.90  hyperbolic bound  sampler
                  cpu 1  U=0.20/0.90  hyperbolic bound  sample-scaler
                memory: 65 MiB of 512 MiB; network: 0 B/s of 10 MB/s
                """, second.toText());
        assertEquals(List.of(List.of("sampler"), List.of("sample-scaler")), second.startGroups());
        assertEquals(Set.of("sampler", "sample-scaler"), p.active());
        assertEquals(Map.of("sampler", 0, "sample-scaler", 1), p.cpuAssignment());
    }

    @Test
    void installBothAtOnceInEitherOrderGivesTheSamePlan() {
        Plan a = new Planner(CAPS).plan(Change.install(scaler(), sampler()));
        Plan b = new Planner(CAPS).plan(Change.install(sampler(), scaler()));
        assertEquals(a.toText(), b.toText());
        assertEquals(List.of("sampler", "sample-scaler"), a.startOrder());
    }

    @Test
    void uninstallProviderStopsDependentsFirst() {
        Planner p = cell();
        Plan plan = p.plan(Change.uninstall("sampler"));
        assertEquals("""
                plan: uninstall sampler 1.0.0
                actions:
                  STOP     sample-scaler  input 'x' of 'sample-scaler': no provider of arflex.Sample 1.x (state)
                  STOP     sampler        uninstalled
                stop order: sample-scaler, sampler
                start order: (none)
                wiring: none
                cpus:
                  cpu 0  U=0.00/0.90  none
                  cpu 1  U=0.00/0.90  none
                memory: 0 B of 512 MiB; network: 0 B/s of 10 MB/s
                not active:
                  sample-scaler  input 'x' of 'sample-scaler': no provider of arflex.Sample 1.x (state)
                """, plan.toText());
        // Reinstall brings the consumer back by itself.
        p.apply(Change.uninstall("sampler"));
        Plan back = p.apply(Change.install(sampler()));
        assertEquals(List.of("sampler", "sample-scaler"), back.startOrder());
    }

    @Test
    void updateRestartsOnlyWhatIsAffected() {
        Planner p = cell();
        // Same ports: only the provider restarts.
        Plan same = p.plan(Change.replace(C.of("sampler").version("1.0.1").out("out", S).timing(1, 1, 0.3, 90)
                .mem(64 * MIB).crit(3).build()));
        assertEquals(List.of(new Plan.Action(Plan.Op.RESTART, "sampler", "replaced 1.0.0 -> 1.0.1")), same.actions());
        // A new minor port version: the consumer's segment changes too.
        Plan minor = p.plan(Change.replace(C.of("sampler").version("1.1.0").out("out", S, "1.1", Method.STATE)
                .timing(1, 1, 0.3, 90).mem(64 * MIB).crit(3).build()));
        assertEquals("""
                plan: update sampler 1.0.0 -> 1.1.0
                actions:
                  RESTART  sample-scaler  provider port sampler.out changed (arflex.Sample 1.0 state depth 1 -> arflex.Sample 1.1 state depth 1)
                  RESTART  sampler        replaced 1.0.0 -> 1.1.0
                stop order: sample-scaler, sampler
                start order: sampler, sample-scaler
                wiring:
                  sample-scaler.x <- sampler.out
                cpus:
                  cpu 0  U=0.30/0.90  hyperbolic bound  sampler
                  cpu 1  U=0.20/0.90  hyperbolic bound  sample-scaler
                memory: 65 MiB of 512 MiB; network: 0 B/s of 10 MB/s
                """, minor.toText());
        // A new major version no longer feeds the consumer.
        Plan major = p.plan(Change.replace(C.of("sampler").version("2.0.0").out("out", S, "2.0", Method.STATE)
                .timing(1, 1, 0.3, 90).mem(64 * MIB).crit(3).build()));
        assertEquals("input 'x' of 'sample-scaler': no provider of arflex.Sample 1.x (state); not matching: "
                + "sampler.out arflex.Sample 2.0 (state)", major.action("sample-scaler").get().reason());
        assertEquals(Plan.Op.STOP, major.action("sample-scaler").get().op());
        assertEquals(Plan.Op.RESTART, major.action("sampler").get().op());
    }

    @Test
    void identicalReplaceIsANoOp() {
        Planner p = cell();
        assertTrue(p.plan(Change.replace(sampler())).isEmpty());
    }

    @Test
    void shrinkingCapacityDropsLowestCriticalityAndCascades() {
        Planner p = new Planner(Capacities.of(1, 1.0, 512 * MIB, 0));
        p.apply(Change.install(
                C.of("safety").timing(10, 10, 1, 95).mem(100 * MIB).crit(10).build(),
                C.of("logger").service().mem(200 * MIB).crit(1).build(),
                C.of("camera").out("img", "arflex.Image", "1.0", Method.FRAME).mem(150 * MIB).crit(2).build(),
                C.of("vision").in("img", "arflex.Image", "1.0", Method.FRAME, java.util.Optional.empty(), false)
                        .mem(20 * MIB).crit(2).build()));
        assertEquals(Set.of("camera", "logger", "safety", "vision"), p.active());
        // 300 MiB: safety (100) first, then camera+vision (effective 2), logger (1) no longer fits.
        Plan plan = p.plan(Change.capacities(Capacities.of(1, 1.0, 300 * MIB, 0)));
        assertEquals(List.of(new Plan.Action(Plan.Op.STOP, "logger", "memory: 200 MiB requested, 30 MiB free")),
                plan.actions());
        // 200 MiB: camera's group goes too, and vision with it.
        plan = p.plan(Change.capacities(Capacities.of(1, 1.0, 200 * MIB, 0)));
        assertEquals("""
                plan: capacities memory 512 MiB -> 200 MiB
                actions:
                  STOP     camera  memory: 150 MiB requested, 100 MiB free
                  STOP     logger  memory: 200 MiB requested, 100 MiB free
                  STOP     vision  input 'img' of 'vision': provider 'camera' was refused admission
                stop order: vision, logger, camera
                start order: (none)
                wiring: none
                cpus:
                  cpu 0  U=0.10/1.00  hyperbolic bound  safety
                memory: 100 MiB of 200 MiB; network: 0 B/s of 0 B/s
                not active:
                  camera  memory: 150 MiB requested, 100 MiB free
                  logger  memory: 200 MiB requested, 100 MiB free
                  vision  input 'img' of 'vision': provider 'camera' was refused admission
                """, plan.toText());
        // Applying and growing again brings them back.
        p.apply(Change.capacities(Capacities.of(1, 1.0, 200 * MIB, 0)));
        Plan grow = p.apply(Change.capacities(Capacities.of(1, 1.0, 512 * MIB, 0)));
        assertEquals(List.of("camera", "logger", "vision"), grow.startOrder());
        assertEquals("admitted now (was refused: memory: 150 MiB requested, 100 MiB free); cpu 0: hyperbolic bound holds (U=0.30)",
                grow.action("camera").get().reason());
    }

    @Test
    void losingACpuMovesItsTasks() {
        Planner p = new Planner(Capacities.of(2, 0.9, 512 * MIB, 0));
        p.apply(Change.install(C.of("a").timing(10, 10, 3, 5).build(), C.of("b").timing(10, 10, 2, 5).build()));
        assertEquals(Map.of("a", 0, "b", 1), p.cpuAssignment());
        Plan plan = p.apply(Change.capacities(Capacities.of(1, 0.9, 512 * MIB, 0)));
        assertEquals(List.of(new Plan.Action(Plan.Op.RESTART, "b", "moved cpu 1 -> 0")), plan.actions());
        assertEquals(Map.of("a", 0, "b", 0), p.cpuAssignment());
        // Growing again does not move anything back: running components keep their CPU.
        assertTrue(p.plan(Change.capacities(Capacities.of(2, 0.9, 512 * MIB, 0))).isEmpty());
    }

    @Test
    void cpuCapacityChangeAndMeasuredWcet() {
        Planner p = cell();
        Plan shrink = p.plan(Change.capacities(Capacities.of(1, 0.4, 512 * MIB, 10_000_000)));
        assertEquals(List.of(new Plan.Action(Plan.Op.STOP, "sample-scaler",
                "cpu 0: utilisation 0.50 with 'sample-scaler' exceeds cap 0.40")), shrink.actions());
        assertTrue(shrink.title().equals("capacities cpus 0(0.9) 1(0.9) -> 0(0.4)"), shrink.title());
        Plan overrun = p.plan(Change.measuredWcet("sample-scaler", 950_000));
        assertEquals(List.of(new Plan.Action(Plan.Op.STOP, "sample-scaler",
                "cpu 1: utilisation 0.95 with 'sample-scaler' exceeds cap 0.90; cpu 0: utilisation 1.25 with "
                        + "'sample-scaler' exceeds cap 0.90 (measured WCET 950 us > declared 200 us)")),
                overrun.actions());
        assertEquals("measured WCET sample-scaler 950 us", overrun.title());
    }

    @Test
    void dryRunLeavesTheStateAndApplyExecutesTheSamePlan() {
        Planner p = cell();
        String before = p.current().toText();
        Change ch = Change.builder().uninstall("sampler").install(C.of("other").out("out", S).build()).build();
        Plan dry = p.plan(ch);
        assertEquals(before, p.current().toText());
        assertTrue(p.current().isEmpty());
        Plan real = p.apply(ch);
        assertEquals(dry.toText(), real.toText());
        assertEquals(real.activeAfter(), p.active());
        assertTrue(p.current().isEmpty());
        // The consumer was rewired to the new provider.
        assertEquals("input 'x' now from other.out (was sampler.out)", real.action("sample-scaler").get().reason());
    }

    @Test
    void controlLoopStartsAsOneGroup() {
        Planner p = new Planner(Capacities.of(2, 0.9, 512 * MIB, 0));
        Plan plan = p.apply(Change.install(
                C.of("robot").in("traj", "arflex.Trajectory").in("corr", "arflex.Correction")
                        .out("state", "arflex.JointState").build(),
                C.of("vision").in("state", "arflex.JointState").out("pose", "arflex.Pose").build(),
                C.of("correction").in("pose", "arflex.Pose").out("corr", "arflex.Correction").build(),
                C.of("trajectory").out("traj", "arflex.Trajectory").build()));
        assertEquals(List.of(List.of("trajectory"), List.of("correction", "robot", "vision")), plan.startGroups());
        assertEquals(List.of(List.of("correction", "robot", "vision")), plan.cycles());
        assertTrue(plan.toText().contains("cycles:\n  {correction, robot, vision}\n"), plan.toText());
        // Losing the trajectory takes the loop down.
        Plan down = p.plan(Change.uninstall("trajectory"));
        assertEquals(Set.of("correction", "robot", "trajectory", "vision"),
                Set.copyOf(down.stopOrder()));
        assertEquals("trajectory", down.stopOrder().get(3));
    }

    @Test
    void blockingCascadesAndUnblockingRestores() {
        Planner p = cell();
        Plan b = p.apply(Change.block("sampler", "Failed: 3 restarts in 10 s"));
        assertEquals(List.of(
                new Plan.Action(Plan.Op.STOP, "sample-scaler", "input 'x' of 'sample-scaler': provider 'sampler' is blocked"),
                new Plan.Action(Plan.Op.STOP, "sampler", "blocked: Failed: 3 restarts in 10 s")), b.actions());
        assertEquals(Map.of("sampler", "Failed: 3 restarts in 10 s"), p.blocked());
        Plan u = p.apply(Change.unblock("sampler"));
        assertEquals(List.of("sampler", "sample-scaler"), u.startOrder());
        assertTrue(u.action("sampler").get().reason().startsWith("unblocked; cpu 0"), u.action("sampler").toString());
    }

    @Test
    void aSecondProviderMakesTheInputAmbiguous() {
        Planner p = cell();
        Plan plan = p.plan(Change.install(C.of("sampler2").out("out", S).build()));
        assertEquals(new Plan.Action(Plan.Op.STOP, "sample-scaler",
                "input 'x' of 'sample-scaler': ambiguous: sampler.out, sampler2.out"), plan.action("sample-scaler").get());
        assertEquals(Plan.Op.START, plan.action("sampler2").get().op());
    }

    @Test
    void optionalProviderArrivingRewiresTheConsumerWhileItRuns() {
        Planner p = new Planner(CAPS);
        p.apply(Change.install(C.of("display").inOptional("x", S).build()));
        assertEquals(Set.of("display"), p.active());
        Plan plan = p.apply(Change.install(sampler()));
        assertEquals(new Plan.Action(Plan.Op.REBIND, "display", "input 'x' now from sampler.out"),
                plan.action("display").get());
        // Rebinding is not a restart: the consumer is neither stopped nor started.
        assertEquals(List.of("sampler"), plan.startOrder());
        assertEquals(List.of(), plan.stopOrder());
        assertEquals(List.of(new Wire("display", "x", "sampler", "out")), plan.wiringOf("display"));
        plan = p.plan(Change.uninstall("sampler"));
        assertEquals(new Plan.Action(Plan.Op.REBIND, "display", "input 'x' lost sampler.out"),
                plan.action("display").get());
        assertEquals(List.of("sampler"), plan.stopOrder());
        assertTrue(plan.toText().contains("REBIND   display"), plan.toText());
    }

    /** Issue 15: losing a guard is never a silent rewiring of the arm. */
    @Test
    void losingTheProviderOfASafetyInputIsAHoldNotARebind() {
        Planner p = new Planner(CAPS);
        p.apply(Change.install(C.of("arm").inSafety("safety").build()));
        assertEquals(Set.of("arm"), p.active(), "the arm starts without a guard (and holds)");
        Plan arrive = p.apply(Change.install(C.of("guard").out("safety", "arflex.SafetyState").build()));
        assertEquals(new Plan.Action(Plan.Op.REBIND, "arm", "input 'safety' now from guard.safety"),
                arrive.action("arm").get());
        Plan lose = p.plan(Change.uninstall("guard"));
        assertEquals(new Plan.Action(Plan.Op.HOLD, "arm", "safety input 'safety' lost guard.safety: protective stop "
                + "until a guard is bound and the operator resets"), lose.action("arm").get());
        assertEquals(List.of(lose.action("arm").get()), lose.holds());
        assertEquals(List.of(), lose.rebinds());
        assertEquals(lose.holds(), lose.rewires());
        assertTrue(lose.toText().contains("HOLD     arm"), lose.toText());
        // the same when the guard fails (blocked) instead of being uninstalled
        Plan block = p.plan(Change.block("guard", "Failed: 3 restarts in 10 s"));
        assertEquals(Plan.Op.HOLD, block.action("arm").get().op());
        assertEquals(List.of(), block.stopOrder().stream().filter("arm"::equals).toList(), "the arm is not stopped");
    }

    @Test
    void inconsistentChangesAreRefusedNamingTheComponent() {
        Planner p = cell();
        String before = p.current().toText();
        assertEquals("install 'sampler': already installed (version 1.0.0); use replace",
                assertThrows(IllegalArgumentException.class, () -> p.plan(Change.install(sampler()))).getMessage());
        assertEquals("replace 'ghost': not installed; use install",
                assertThrows(IllegalArgumentException.class, () -> p.apply(Change.replace(C.of("ghost").build())))
                        .getMessage());
        assertEquals("uninstall 'ghost': not installed",
                assertThrows(IllegalArgumentException.class, () -> p.apply(Change.uninstall("ghost"))).getMessage());
        assertEquals("unblock 'sampler': not blocked",
                assertThrows(IllegalArgumentException.class, () -> p.apply(Change.unblock("sampler"))).getMessage());
        assertEquals("measured WCET for 'ghost': not installed",
                assertThrows(IllegalArgumentException.class, () -> p.apply(Change.measuredWcet("ghost", 5)))
                        .getMessage());
        assertEquals("component 'sampler' is both uninstalled and installed in one change",
                assertThrows(IllegalArgumentException.class,
                        () -> p.apply(Change.builder().uninstall("sampler").put(sampler()).build())).getMessage());
        assertEquals(before, p.current().toText());
    }

    @Test
    void putInstallsOrReplaces() {
        Planner p = new Planner(CAPS);
        assertEquals("install sampler 1.0.0", p.apply(Change.put(sampler())).title());
        Plan plan = p.apply(Change.put(C.of("sampler").version("1.2.0").out("out", S).timing(1, 1, 0.3, 90)
                .mem(64 * MIB).crit(3).build()));
        assertEquals("update sampler 1.0.0 -> 1.2.0", plan.title());
        assertFalse(plan.isEmpty());
    }

    @Test
    void measuredWcetCanBeClearedAgain() {
        Planner p = cell();
        p.apply(Change.measuredWcet("sample-scaler", 950_000));
        assertEquals(Set.of("sampler"), p.active());
        assertEquals(Map.of("sample-scaler", 950_000L), p.measuredWcetNs());
        Plan back = p.apply(Change.measuredWcet("sample-scaler", 0));
        assertEquals(List.of("sample-scaler"), back.startOrder());
        assertTrue(back.action("sample-scaler").get().reason().startsWith("admitted now (was refused: cpu 1: utilisation 0.95"),
                back.action("sample-scaler").get().reason());
        assertEquals(Map.of(), p.measuredWcetNs());
    }
}
