package org.arflex.cell;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.file.Files;
import java.nio.file.Path;
import java.util.List;
import java.util.Map;
import org.arflex.contract.Contract;
import org.arflex.contract.ContractParser;
import org.arflex.contract.Filter;
import org.arflex.contract.PortSpec;
import org.junit.jupiter.api.Test;

/** The cell components' contracts (trajectory, force-guard, teach, tools) parse and validate. */
class CellContractsTest {

    private static final List<String> COMPONENTS =
            List.of("trajectory", "force-guard", "teach", "tool-gripper", "tool-spindle");

    private static Contract load(String name) throws Exception {
        Path p = Path.of("..", name, "src/main/resources/OSGI-INF/arflex", name + ".xml");
        return ContractParser.create().parse(Files.readString(p), p.toString());
    }

    @Test
    void everyContractIsValid() throws Exception {
        for (String n : COMPONENTS) {
            Contract c = load(n);
            assertEquals(n, c.name());
            assertEquals(n, c.executable());
        }
    }

    @Test
    void toolsProvideTheSameToolPort() throws Exception {
        PortSpec g = load("tool-gripper").port("tool").orElseThrow();
        PortSpec s = load("tool-spindle").port("tool").orElseThrow();
        assertEquals(PortSpec.Direction.OUT, g.direction());
        assertEquals(g.direction(), s.direction());
        assertEquals("arflex.ToolState", g.type());
        assertEquals(g.type(), s.type());
        assertEquals(g.typeVersion(), s.typeVersion());
        assertEquals(g.method(), s.method());
        assertEquals("tool", load("tool-gripper").attributes().get("role"));
        assertEquals("tool", load("tool-spindle").attributes().get("role"));
    }

    @Test
    void motionComponentsObeyTheSafetyPortTheGuardProvides() throws Exception {
        PortSpec out = load("force-guard").port("safety").orElseThrow();
        PortSpec in = load("trajectory").port("safety").orElseThrow();
        assertEquals(out.type(), in.type());
        assertEquals(out.method(), in.method());
        assertTrue(in.optional());
        assertTrue(load("trajectory").movesHardware());
        // The tools move hardware too: the same safety input, a declared one (SPEC 6.8).
        Map<String, String> guard = load("force-guard").attributes();
        for (String tool : List.of("tool-gripper", "tool-spindle")) {
            PortSpec s = load(tool).port("safety").orElseThrow();
            assertEquals(PortSpec.Direction.IN, s.direction());
            assertEquals(out.type(), s.type(), tool);
            assertEquals(out.typeVersion(), s.typeVersion(), tool);
            assertEquals(out.method(), s.method(), tool);
            assertTrue(s.safety(), tool + ".safety must be a declared safety input");
            assertTrue(load(tool).movesHardware(), tool);
            assertTrue(filterOf(tool, "safety").matches(guard), tool + ".safety must bind the force guard");
        }
    }

    @Test
    void inputFiltersSelectTheIntendedProviders() throws Exception {
        Map<String, String> guard = load("force-guard").attributes();
        Map<String, String> robot = Map.of("role", "robot", "simulated", "true", "axes", "6");
        Map<String, String> sampleSource = Map.of("role", "source");
        for (String n : List.of("trajectory", "teach")) {
            assertTrue(filterOf(n, "safety").matches(guard), n + ".safety must bind the force guard");
            assertTrue(filterOf(n, "joint_state").matches(robot), n + ".joint_state must bind the robot");
        }
        assertTrue(filterOf("force-guard", "wrench").matches(robot));
        // A tool's optional command input must not pick up an unrelated arflex.Sample source.
        assertTrue(!filterOf("tool-gripper", "command").matches(sampleSource));
        assertTrue(!filterOf("tool-spindle", "command").matches(sampleSource));
        // trajectory's tool input takes either tool (a swap rebinds it), never a motion source.
        for (String tool : List.of("tool-gripper", "tool-spindle")) {
            assertTrue(filterOf("trajectory", "tool").matches(load(tool).attributes()), "trajectory.tool must bind " + tool);
        }
        assertTrue(!filterOf("trajectory", "tool").matches(load("teach").attributes()));
        PortSpec in = load("trajectory").port("tool").orElseThrow();
        PortSpec out = load("tool-gripper").port("tool").orElseThrow();
        assertEquals(out.type(), in.type());
        assertTrue(in.optional(), "trajectory runs without a tool (the flange)");
    }

    private static Filter filterOf(String component, String port) throws Exception {
        PortSpec in = load(component).port(port).orElseThrow();
        return Filter.parse(in.binding().orElseThrow().filter().orElseThrow());
    }
}
