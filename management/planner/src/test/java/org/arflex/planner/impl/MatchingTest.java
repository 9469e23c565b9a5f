package org.arflex.planner.impl;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.List;
import java.util.Optional;
import org.arflex.contract.Binding;
import org.arflex.contract.PortSpec.Method;
import org.junit.jupiter.api.Test;
import org.arflex.planner.Satisfaction;
import org.arflex.planner.Wire;

class MatchingTest {

    private static final String S = "arflex.Sample";

    @Test
    void sameTypeVersionAndMethodWires() {
        Resolver r = new Resolver();
        r.put(C.of("sampler").out("out", S).build());
        ResolveDelta d = r.put(C.of("sample-scaler").in("x", S).out("y", S).build());
        assertEquals(List.of(new Wire("sample-scaler", "x", "sampler", "out")), r.wires());
        assertTrue(r.isSatisfied("sample-scaler"));
        assertEquals(List.of(new Wire("sample-scaler", "x", "sampler", "out")), d.wiresAdded());
        assertEquals(List.of("sample-scaler"), List.copyOf(d.becameSatisfied()));
    }

    @Test
    void missingProviderIsNamed() {
        Resolver r = new Resolver();
        r.put(C.of("sample-scaler").in("x", S).build());
        Satisfaction s = r.satisfaction("sample-scaler");
        assertFalse(s.satisfied());
        assertEquals(List.of("input 'x' of 'sample-scaler': no provider of arflex.Sample 1.x (state)"), s.reasons());
    }

    @Test
    void providerMinorMustBeAtLeastConsumerMinorAndMajorEqual() {
        Resolver r = new Resolver();
        r.put(C.of("old").out("o", S, "1.1", Method.STATE).build());
        r.put(C.of("next").out("o", S, "2.3", Method.STATE).build());
        r.put(C.of("c").in("x", S, "1.2", Method.STATE, Optional.empty(), false).build());
        assertFalse(r.isSatisfied("c"));
        assertEquals("input 'x' of 'c': no provider of arflex.Sample 1.2+ (state); not matching: "
                + "next.o arflex.Sample 2.3 (state), old.o arflex.Sample 1.1 (state)",
                r.satisfaction("c").reasons().get(0));
        r.put(C.of("newer").out("o", S, "1.4", Method.STATE).build());
        assertEquals(List.of(new Wire("c", "x", "newer", "o")), r.wires());
        assertTrue(r.isSatisfied("c"));
    }

    @Test
    void methodMustBeEqual() {
        Resolver r = new Resolver();
        r.put(C.of("p").out("o", S, "1.0", Method.STREAM).build());
        r.put(C.of("c").in("x", S).build());
        assertTrue(r.wires().isEmpty());
        assertTrue(r.satisfaction("c").reasons().get(0).contains("p.o arflex.Sample 1.0 (stream)"));
    }

    @Test
    void typeNameMustBeEqual() {
        Resolver r = new Resolver();
        r.put(C.of("p").out("o", "arflex.JointState").build());
        r.put(C.of("c").in("x", S).build());
        assertTrue(r.wires().isEmpty());
    }

    @Test
    void ambiguityNamesAllCandidates() {
        Resolver r = new Resolver();
        r.put(C.of("b").out("y", S).build());
        r.put(C.of("c").out("z", S).build());
        r.put(C.of("a").in("x", S).build());
        assertEquals(List.of("input 'x' of 'a': ambiguous: b.y, c.z"), r.satisfaction("a").reasons());
        assertTrue(r.wires().isEmpty());
        // Removing one candidate resolves the ambiguity.
        ResolveDelta d = r.remove("c");
        assertEquals(List.of(new Wire("a", "x", "b", "y")), r.wires());
        assertTrue(d.becameSatisfied().contains("a"));
        assertTrue(d.rewired().contains("a"));
    }

    @Test
    void explicitBindingPicksOneOfSeveral() {
        Resolver r = new Resolver();
        r.put(C.of("b").out("y", S).build());
        r.put(C.of("c").out("z", S).build());
        r.put(C.of("a").inFrom("x", S, "c", "z").build());
        assertEquals(List.of(new Wire("a", "x", "c", "z")), r.wires());
    }

    @Test
    void explicitBindingReasons() {
        Resolver r = new Resolver();
        r.put(C.of("a").inFrom("x", S, "b", "y").build());
        assertEquals("input 'x' of 'a': explicit provider 'b.y' is not installed", r.satisfaction("a").reasons().get(0));
        r.put(C.of("b").out("q", S).build());
        assertEquals("input 'x' of 'a': 'b' has no output 'y'", r.satisfaction("a").reasons().get(0));
        r.put(C.of("b").out("y", "arflex.Pose", "2.0", Method.STREAM).build());
        assertEquals("input 'x' of 'a': b.y is arflex.Pose 2.0 (stream), needs arflex.Sample 1.x (state)",
                r.satisfaction("a").reasons().get(0));
        r.put(C.of("b").out("y", S).build());
        assertTrue(r.isSatisfied("a"));
    }

    @Test
    void filterBindingMatchesProviderAttributes() {
        Resolver r = new Resolver();
        r.put(C.of("sim-robot").attr("role", "robot").attr("sim", "true").out("state", S).build());
        r.put(C.of("real-robot").attr("role", "robot").attr("sim", "false").out("state", S).build());
        r.put(C.of("ctl").inFilter("x", S, "(&(role=robot)(sim=true))").build());
        assertEquals(List.of(new Wire("ctl", "x", "sim-robot", "state")), r.wires());
        r.put(C.of("ctl2").inFilter("x", S, "(role=camera)").build());
        assertEquals("input 'x' of 'ctl2': no provider of arflex.Sample 1.x (state) matching (role=camera); "
                + "not matching: real-robot.state (filter does not match), sim-robot.state (filter does not match)",
                r.satisfaction("ctl2").reasons().get(0));
        r.put(C.of("ctl3").inFilter("x", S, "(role=robot)").build());
        assertEquals(List.of("input 'x' of 'ctl3': ambiguous: real-robot.state, sim-robot.state"),
                r.satisfaction("ctl3").reasons());
    }

    @Test
    void invalidFilterIsReported() {
        Resolver r = new Resolver();
        r.put(C.of("p").out("o", S).build());
        r.put(C.of("c").inFilter("x", S, "(role=robot").build());
        assertFalse(r.isSatisfied("c"));
        assertTrue(r.satisfaction("c").reasons().get(0).startsWith("input 'x' of 'c': invalid binding filter: "),
                r.satisfaction("c").reasons().get(0));
    }

    @Test
    void optionalInputsNeverBlock() {
        Resolver r = new Resolver();
        r.put(C.of("c").inOptional("x", S).build());
        Satisfaction s = r.satisfaction("c");
        assertTrue(s.satisfied());
        assertEquals(List.of("optional input 'x' of 'c': no provider of arflex.Sample 1.x (state) (not blocking)"),
                s.notes());
        r.put(C.of("p").in("q", "arflex.Missing").out("o", S).build());
        // Wired to an unsatisfied provider: still satisfied itself.
        assertEquals(List.of(new Wire("c", "x", "p", "o")), r.wires());
        assertTrue(r.isSatisfied("c"));
        assertFalse(r.isSatisfied("p"));
    }

    @Test
    void satisfactionIsTransitive() {
        Resolver r = new Resolver();
        r.put(C.of("b").in("q", "arflex.Pose").out("y", S).build());
        r.put(C.of("a").in("x", S).build());
        assertFalse(r.isSatisfied("a"));
        assertEquals(List.of("input 'x' of 'a': provider 'b' is Unsatisfied"), r.satisfaction("a").reasons());
        ResolveDelta d = r.put(C.of("pose").out("p", "arflex.Pose").build());
        assertEquals(List.of("a", "b", "pose"), List.copyOf(d.becameSatisfied()));
        d = r.remove("pose");
        assertEquals(List.of("a", "b"), List.copyOf(d.becameUnsatisfied()));
    }

    @Test
    void controlLoopCycleIsLegalAndReported() {
        Resolver r = new Resolver();
        r.put(C.of("trajectory").out("traj", "arflex.Trajectory").build());
        r.put(C.of("robot").in("traj", "arflex.Trajectory").in("corr", "arflex.Correction")
                .out("state", "arflex.JointState").build());
        r.put(C.of("vision").in("state", "arflex.JointState").out("pose", "arflex.Pose").build());
        r.put(C.of("correction").in("pose", "arflex.Pose").out("corr", "arflex.Correction").build());
        assertEquals(List.of("correction", "robot", "trajectory", "vision"), List.copyOf(r.satisfied()));
        assertEquals(List.of(List.of("correction", "robot", "vision")), r.cycles());
        assertEquals(List.of("in cycle: robot -> vision -> correction -> robot"), r.satisfaction("robot").notes());
        // Without the trajectory the whole loop is unsatisfied, each saying why.
        ResolveDelta d = r.remove("trajectory");
        assertEquals(List.of("correction", "robot", "vision"), List.copyOf(d.becameUnsatisfied()));
        assertEquals(List.of("input 'traj' of 'robot': no provider of arflex.Trajectory 1.x (state)",
                "input 'corr' of 'robot': provider 'correction' is Unsatisfied"), r.satisfaction("robot").reasons());
        assertEquals(List.of("input 'state' of 'vision': provider 'robot' is Unsatisfied"),
                r.satisfaction("vision").reasons());
        d = r.put(C.of("trajectory").out("traj", "arflex.Trajectory").build());
        assertEquals(List.of("correction", "robot", "trajectory", "vision"), List.copyOf(d.becameSatisfied()));
    }

    @Test
    void selfBindingOnlyWhenExplicit() {
        Resolver r = new Resolver();
        r.put(C.of("integrator").in("prev", S).out("y", S).build());
        assertFalse(r.isSatisfied("integrator"));
        r.put(C.of("integrator").inFrom("prev", S, "integrator", "y").out("y", S).build());
        assertTrue(r.isSatisfied("integrator"));
        assertEquals(List.of(new Wire("integrator", "prev", "integrator", "y")), r.wires());
        assertEquals(List.of(List.of("integrator")), r.cycles());
    }

    @Test
    void replaceWithIdenticalContractChangesNothing() {
        Resolver r = new Resolver();
        r.put(C.of("p").out("o", S).build());
        assertTrue(r.put(C.of("p").out("o", S).build()).isEmpty());
    }

    @Test
    void errorsNameTheComponent() {
        Resolver r = new Resolver();
        IllegalArgumentException e = assertThrows(IllegalArgumentException.class, () -> r.remove("ghost"));
        assertEquals("cannot remove 'ghost': not installed", e.getMessage());
        e = assertThrows(IllegalArgumentException.class, () -> r.satisfaction("ghost"));
        assertEquals("component 'ghost' is not installed", e.getMessage());
        e = assertThrows(IllegalArgumentException.class,
                () -> r.apply(List.of(C.of("a").build(), C.of("a").build()), List.of()));
        assertEquals("contract 'a' is given twice in one change", e.getMessage());
    }

    @Test
    void bindingRecordHelpersAreUsable() {
        assertEquals(Optional.of("(a=b)"), Binding.filter("(a=b)").filter());
    }
}
