package org.arflex.sim;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.Set;
import java.util.TreeSet;
import java.util.regex.Matcher;
import java.util.regex.Pattern;
import java.util.stream.Collectors;
import org.arflex.contract.Contract;
import org.arflex.contract.ContractException;
import org.arflex.contract.ContractParser;
import org.arflex.contract.PortSpec;
import org.arflex.contract.PropertySpec;
import org.junit.jupiter.api.Test;

/**
 * The simulator's contracts (sim-robot here, the four sim-camera instances beside it) are
 * accepted by the contract validator, agree with their RT halves, and keep the ground truth out
 * of reach of application components (simulator/README.md, "Ground truth").
 */
class SimContractsTest {

    private static final Path BUNDLES = Path.of("..").toAbsolutePath().normalize();
    private final ContractParser parser = ContractParser.create();

    private Contract parse(Path file) throws IOException, ContractException {
        try (var in = Files.newInputStream(file)) {
            return parser.parse(in, file.getFileName().toString());
        }
    }

    private static Path robotContract() {
        return BUNDLES.resolve("sim-robot/src/main/resources/OSGI-INF/arflex/sim-robot.xml");
    }

    private static Path cameraContract(int i) {
        return BUNDLES.resolve("sim-camera/src/main/resources/OSGI-INF/arflex/sim-camera-" + i + ".xml");
    }

    /** Parameter names an RT half looks up: the first string of each kParams row / Param*() call. */
    private static Set<String> rtParams(Path source, Pattern p) throws IOException {
        Matcher m = p.matcher(Files.readString(source, StandardCharsets.UTF_8));
        Set<String> names = new TreeSet<>();
        while (m.find()) {
            names.add(m.group(1));
        }
        return names;
    }

    private static Set<String> props(Contract c) {
        return c.properties().stream().map(PropertySpec::name).collect(Collectors.toCollection(TreeSet::new));
    }

    @Test
    void robotContractIsValidAndMatchesItsRtHalf() throws Exception {
        Contract c = parse(robotContract());
        assertEquals("sim-robot", c.name());
        assertEquals("sim-robot", c.executable());
        assertTrue(c.movesHardware());
        List<String> ports = new ArrayList<>();
        for (PortSpec p : c.ports()) {
            ports.add(p.direction() + " " + p.name() + " " + p.type() + " " + p.method());
        }
        assertEquals(List.of("IN joint_ref arflex.JointRef STATE", "IN safety arflex.SafetyState STATE",
                "OUT joint_state arflex.JointState STATE", "OUT wrench arflex.Wrench STATE",
                "OUT servo_power arflex.Sample STATE"), ports);
        Set<String> rt = rtParams(BUNDLES.resolve("sim-robot/native/sim_robot.cc"),
                Pattern.compile("\\{\"([a-z_]+)\", [-0-9.]+, '[dib]'\\}"));
        assertEquals(20, rt.size(), "parameters found in sim_robot.cc: " + rt);
        assertEquals(rt, props(c), "contract properties == parameters the RT half reads");
    }

    @Test
    void cameraContractsAreValidAndBindTheRobot() throws Exception {
        Set<String> rt = rtParams(BUNDLES.resolve("sim-camera/native/sim_camera.cc"),
                Pattern.compile("Param[IDB]\\(c, \"([a-z_]+)\""));
        rt.add("noise_sigma");
        rt.add("blur_sigma");
        for (int i = 0; i < 4; i++) {
            Contract c = parse(cameraContract(i));
            assertEquals("sim-camera-" + i, c.name());
            assertEquals("sim-camera", c.executable());
            assertEquals(rt, props(c));
            PropertySpec camera = c.properties().stream().filter(p -> p.name().equals("camera")).findFirst().orElseThrow();
            assertTrue(camera.defaultValue().toString().contains(Integer.toString(i)), camera.defaultValue().toString());
            PortSpec in = c.ports().stream().filter(p -> p.direction() == PortSpec.Direction.IN).findFirst().orElseThrow();
            assertEquals("arflex.JointState", in.type());
            assertEquals("sim-robot", in.binding().orElseThrow().component().orElseThrow());
            assertEquals("joint_state", in.binding().orElseThrow().port().orElseThrow());
            PortSpec out = c.ports().stream().filter(p -> p.direction() == PortSpec.Direction.OUT).findFirst().orElseThrow();
            assertEquals("arflex.ImageFrame", out.type());
            assertEquals(PortSpec.Method.FRAME, out.method());
        }
    }

    @Test
    void groundTruthIsNoContractPort() throws Exception {
        // Not offered by the simulator's contracts ...
        List<Contract> all = new ArrayList<>();
        all.add(parse(robotContract()));
        for (int i = 0; i < 4; i++) {
            all.add(parse(cameraContract(i)));
        }
        for (Contract c : all) {
            for (PortSpec p : c.ports()) {
                assertFalse(p.type().startsWith("eval."), c.name() + "." + p.name());
                assertFalse(p.name().equals("truth"), c.name() + "." + p.name());
            }
        }
        // ... and no contract can declare an input of the ground-truth type: it is not a
        // contract port type, so the validator refuses it (and the resolver never sees it).
        String xml = Files.readString(cameraContract(0), StandardCharsets.UTF_8)
                .replace("name=\"sim-camera-0\"", "name=\"thief\"")
                .replace("type=\"arflex.JointState\"", "type=\"eval.GroundTruth\"")
                .replace("<bind component=\"sim-robot\" port=\"joint_state\"/>", "<bind component=\"sim-robot\" port=\"truth\"/>");
        ContractException e = assertThrows(ContractException.class, () -> parser.parse(xml, "thief.xml"));
        assertTrue(e.getMessage().contains("eval.GroundTruth"), e.getMessage());
    }
}
