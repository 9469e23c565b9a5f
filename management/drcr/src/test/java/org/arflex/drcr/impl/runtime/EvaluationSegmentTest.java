package org.arflex.drcr.impl.runtime;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.Map;
import org.arflex.contract.Contract;
import org.arflex.contract.ContractParser;
import org.arflex.contract.PortTypes;
import org.arflex.drcr.impl.lifecycle.ManualActor;
import org.arflex.drcr.impl.lifecycle.State;
import org.arflex.planner.Capacities;
import org.arflex.planner.Planner;
import org.junit.jupiter.api.Test;

/**
 * The ground-truth segment (simulator README, "Ground truth"): created before the spawn only
 * under arflex.evaluation and only for simulated robots, never bound, removed with the others.
 */
class EvaluationSegmentTest {

    private static final String TRUTH = "/arflex.t.robot.out.truth";

    private final ManualActor actor = new ManualActor();
    private final FakeLauncher launcher = new FakeLauncher();
    private final List<String> log = new ArrayList<>();

    private Cell cell(boolean evaluation) {
        return new Cell(new Cell.Config("t", 1000, 1000, true, PortTypes.builtin(), () -> 1_000_000_000L, evaluation),
                actor, launcher, new Planner(Capacities.of(2, 1.0, 1L << 30, 1_000_000_000L)), log::add);
    }

    private static String contract(String name, String attributes, String ports) {
        return "<component xmlns=\"urn:arflex:contract:1\" name=\"" + name + "\" version=\"1.0.0\">"
                + "<implementation executable=\"" + name + "\" task=\"periodic\" movesHardware=\"false\"/>"
                + "<attributes>" + attributes + "</attributes><ports>" + ports + "</ports>"
                + "<timing period=\"1ms\" deadline=\"1ms\" wcet=\"50us\" priority=\"80\"/>"
                + "<resources memory=\"1MiB\" network=\"0\"/><criticality>5</criticality>"
                + "<fault restart=\"permanent\" intensity=\"2\" window=\"10s\" backoff=\"100ms\" safe=\"hold\""
                + " heartbeatTimeout=\"100ms\"/></component>";
    }

    private static final String ROBOT = contract("robot",
            "<attribute name=\"role\" value=\"robot\"/><attribute name=\"simulated\" value=\"true\"/>",
            "<out name=\"y\" type=\"arflex.Sample\" typeVersion=\"1.0\" method=\"state\"/>");
    /** Simulated, but not a robot (e.g. a camera): no ground truth. */
    private static final String CAMERA = contract("cam",
            "<attribute name=\"role\" value=\"camera\"/><attribute name=\"simulated\" value=\"true\"/>",
            "<in name=\"x\" type=\"arflex.Sample\" typeVersion=\"1.0\" method=\"state\"><bind component=\"robot\" port=\"y\"/></in>");
    /** A robot that is not simulated: no ground truth either. */
    private static final String REAL = contract("real", "<attribute name=\"role\" value=\"robot\"/>",
            "<out name=\"y\" type=\"arflex.Sample\" typeVersion=\"1.0\" method=\"state\"/>");

    private void install(Cell cell, String xml) throws Exception {
        Contract c = ContractParser.create(PortTypes.builtin()).parse(xml, "test.xml");
        assertTrue(actor.call(() -> cell.install(c, c.name().hashCode(), Path.of("/nonexistent/" + c.name())), 0), log::toString);
        actor.runAll();
    }

    private void shutdown(Cell cell) {
        actor.call(() -> {
            cell.shutdownAll("test end");
            return null;
        }, 0);
        actor.runAll();
        assertTrue(launcher.running.isEmpty(), "RT halves left running: " + launcher.running.keySet());
        assertTrue(launcher.openOutputs.isEmpty(), "segments left: " + launcher.openOutputs);
    }

    private Map<String, String> segments(Cell cell, String name) {
        return Snapshots.instance(cell, cell.instance(name).orElseThrow()).evaluationSegments;
    }

    @Test
    void underTheSwitchTheRobotGetsItsTruthSegmentNeverBoundAndRemovedAfter() throws Exception {
        Cell cell = cell(true);
        install(cell, ROBOT);
        install(cell, CAMERA);
        install(cell, REAL);
        assertEquals(State.ACTIVE, cell.instance("robot").orElseThrow().life.state(), log::toString);
        assertEquals(State.ACTIVE, cell.instance("cam").orElseThrow().life.state(), log::toString);
        String create = "CREATE " + TRUTH + " eval.GroundTruth 192";
        assertTrue(launcher.events.contains(create), launcher.events.toString());
        assertTrue(launcher.events.indexOf(create) < launcher.events.indexOf("robot LAUNCH"), "created before the spawn");
        assertEquals(1, launcher.events.stream().filter(e -> e.contains(".out.truth")).count(),
                "only the simulated robot gets one, once, and no BIND names it: " + launcher.events);
        assertTrue(launcher.events.contains("cam BIND x /arflex.t.robot.out.y"), launcher.events.toString());
        assertEquals(Map.of("truth", TRUTH), segments(cell, "robot"));
        assertEquals(Map.of(), segments(cell, "cam"));
        assertEquals(Map.of(), segments(cell, "real"));
        assertEquals(1, launcher.openOutputs.get(TRUTH));
        // arflex:summary reads it through the port reader as eval.GroundTruth; no one else has one
        PortValues.Ref ref = actor.call(() -> PortValues.evaluationRef(cell, "robot", "truth"), 0);
        assertEquals(TRUTH, ref.segment());
        assertEquals(EvaluationSegments.TRUTH_TYPE, ref.type());
        assertEquals(null, actor.call(() -> PortValues.evaluationRef(cell, "cam", "truth"), 0));
        assertEquals(null, actor.call(() -> PortValues.evaluationRef(cell, "robot", "y"), 0));
        assertEquals(null, actor.call(() -> PortValues.evaluationRef(cell, "nobody", "truth"), 0));

        // a crash and restart keeps it (as every output segment); an uninstall removes it
        launcher.running.get("robot").crash(139, "killed by signal 11");
        actor.runAll();
        assertEquals(1, launcher.openOutputs.get(TRUTH), launcher.openOutputs.toString());
        actor.call(() -> {
            cell.uninstall("robot", "bundle stopped");
            return null;
        }, 0);
        actor.runAll();
        assertFalse(launcher.openOutputs.containsKey(TRUTH), "removed with the other segments: " + launcher.openOutputs);
        install(cell, ROBOT);
        assertEquals(1, launcher.openOutputs.get(TRUTH), "created again at the reinstall");
        shutdown(cell);
    }

    @Test
    void withoutTheSwitchThereIsNoTruthSegment() throws Exception {
        Cell cell = cell(false);
        install(cell, ROBOT);
        assertEquals(State.ACTIVE, cell.instance("robot").orElseThrow().life.state(), log::toString);
        assertTrue(launcher.events.stream().noneMatch(e -> e.contains("truth")), launcher.events.toString());
        assertEquals(Map.of(), segments(cell, "robot"));
        shutdown(cell);
    }

    /** The port reader decodes the record by the fields of simulator/include/arflex_sim/ground_truth.h. */
    @Test
    void theGroundTruthTypeHasTheHeadersLayout() {
        var t = EvaluationSegments.TRUTH_TYPE;
        assertEquals(EvaluationSegments.SIZE, t.size());
        assertEquals(40, t.field("p").orElseThrow().offset(), "the header's static assert");
        assertEquals(3, t.field("p").orElseThrow().count());
        assertEquals(64, t.field("quat").orElseThrow().offset());
        assertEquals(168, t.field("obstacle_contacts").orElseThrow().offset());
        assertEquals(184, t.field("reserved").orElseThrow().offset());
        assertEquals(EvaluationSegments.TYPE, t.name());
        assertEquals(EvaluationSegments.PORT, EvaluationSegments.TRUTH_SPEC.name());
    }
}
