package org.arflex.drcr.impl.services;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.List;
import org.arflex.contract.Contract;
import org.arflex.contract.ContractParser;
import org.arflex.contract.PortTypes;
import org.arflex.planner.Wire;
import org.junit.jupiter.api.Test;

/**
 * The port-format check of deployment sets (D45) on a small cell: {@code traj} writes a joint
 * reference, {@code corr} reads it (by filter) and writes the corrected one, {@code robot} reads
 * that (by filter) and writes its state.
 */
class PortFormatsTest {

    static final String REF_IN = "<in name=\"reference\" type=\"arflex.JointRef\" typeVersion=\"1.0\" method=\"state\">"
            + "<bind filter=\"(role=motion)\"/></in>";
    static final String CORRECTED = "<out name=\"corrected\" type=\"arflex.JointRef\" typeVersion=\"1.0\" method=\"state\"/>";
    static final String ROBOT_IN = "<in name=\"joint_ref\" type=\"arflex.JointRef\" typeVersion=\"1.0\" method=\"state\">"
            + "<bind filter=\"(role=correction)\"/></in>";

    static Contract contract(String name, String version, String role, String ports) throws Exception {
        return ContractParser.create(PortTypes.builtin()).parse("<component xmlns=\"urn:arflex:contract:1\" name=\"" + name
                + "\" version=\"" + version + "\"><implementation executable=\"" + name
                + "\" task=\"periodic\" movesHardware=\"false\"/>"
                + (role == null ? "" : "<attributes><attribute name=\"role\" value=\"" + role + "\"/></attributes>")
                + "<ports>" + ports + "</ports>"
                + "<timing period=\"1ms\" deadline=\"1ms\" wcet=\"50us\" priority=\"80\"/>"
                + "<resources memory=\"1MiB\" network=\"0\"/><criticality>5</criticality>"
                + "<fault restart=\"permanent\" intensity=\"2\" window=\"10s\" backoff=\"100ms\" safe=\"hold\""
                + " heartbeatTimeout=\"100ms\"/></component>", name + ".xml");
    }

    private final PortFormats formats = new PortFormats(PortTypes.builtin());
    private final Contract traj;
    private final Contract corr;
    private final Contract robot;
    private final List<Wire> wires = List.of(new Wire("corr", "reference", "traj", "joint_ref"),
            new Wire("robot", "joint_ref", "corr", "corrected"));

    PortFormatsTest() throws Exception {
        traj = contract("traj", "1.0.0", "motion",
                "<out name=\"joint_ref\" type=\"arflex.JointRef\" typeVersion=\"1.0\" method=\"state\"/>");
        corr = contract("corr", "1.0.0", "correction", REF_IN + CORRECTED);
        robot = contract("robot", "1.0.0", "robot", ROBOT_IN
                + "<out name=\"joint_state\" type=\"arflex.JointState\" typeVersion=\"1.0\" method=\"state\"/>");
    }

    private List<String> check(List<Contract> installs, List<Contract> updates) {
        return formats.check(List.of(traj, corr, robot), wires, installs, updates);
    }

    @Test
    void anUpdateInTheSameFormatPasses() throws Exception {
        assertEquals(List.of(), check(List.of(), List.of(contract("corr", "1.0.1", "correction", REF_IN + CORRECTED))));
    }

    @Test
    void anUpdateThatChangesAnOutputsMethodNamesTheRunningPeerAndBothFormats() throws Exception {
        Contract stream = contract("corr", "2.0.0", "correction", REF_IN
                + "<out name=\"corrected\" type=\"arflex.JointRef\" typeVersion=\"1.0\" method=\"stream\" depth=\"8\"/>");
        assertEquals(List.of("update corr 2.0.0: output 'corrected' changes to arflex.JointRef 1.0 stream, but its peer "
                + "robot.joint_ref (running) reads arflex.JointRef 1.0 state (method stream is not state)"),
                check(List.of(), List.of(stream)));
    }

    @Test
    void anUpdateThatChangesAnOutputsTypeListsTheFieldsOfBoth() throws Exception {
        Contract pose = contract("corr", "2.0.0", "correction", REF_IN
                + "<out name=\"corrected\" type=\"arflex.Sample\" typeVersion=\"1.0\" method=\"state\"/>");
        List<String> p = check(List.of(), List.of(pose));
        assertEquals(1, p.size(), p::toString);
        String want = "update corr 2.0.0: output 'corrected' changes to arflex.Sample 1.0 state, but its peer "
                + "robot.joint_ref (running) reads arflex.JointRef 1.0 state (another type; written: arflex.Sample {";
        assertEquals(want, p.get(0).substring(0, Math.min(want.length(), p.get(0).length())), p.get(0));
        assertEquals(true, p.get(0).contains("; read: arflex.JointRef {"), p.get(0));
    }

    @Test
    void anUpdateThatDropsAnOutputAPeerReadsIsRefused() throws Exception {
        Contract gone = contract("corr", "2.0.0", "correction", REF_IN
                + "<out name=\"corrected2\" type=\"arflex.JointRef\" typeVersion=\"1.0\" method=\"state\"/>");
        assertEquals(List.of("update corr 2.0.0: output 'corrected' is gone, but robot.joint_ref reads it "
                + "(arflex.JointRef 1.0 state)"), check(List.of(), List.of(gone)));
    }

    @Test
    void anUpdatedInputMustStillBeFedByItsRunningProvider() throws Exception {
        Contract in = contract("corr", "2.0.0", "correction", REF_IN.replace("method=\"state\"", "method=\"stream\"")
                + CORRECTED);
        assertEquals(List.of("update corr 2.0.0: input 'reference' changes to arflex.JointRef 1.0 stream, but its peer "
                + "traj.joint_ref (running) writes arflex.JointRef 1.0 state (method state is not stream)"),
                check(List.of(), List.of(in)));
    }

    @Test
    void bothEndsUpdatedTogetherAreCheckedAgainstEachOther() throws Exception {
        String streamOut = "<out name=\"corrected\" type=\"arflex.JointRef\" typeVersion=\"1.0\" method=\"stream\" depth=\"8\"/>";
        Contract c2 = contract("corr", "2.0.0", "correction", REF_IN + streamOut);
        Contract r2 = contract("robot", "2.0.0", "robot", ROBOT_IN.replace("method=\"state\"", "method=\"stream\""));
        assertEquals(List.of(), check(List.of(), List.of(c2, r2)), "the new robot reads the new stream");
        Contract r1 = contract("robot", "1.0.1", "robot", ROBOT_IN);
        assertEquals(List.of("update corr 2.0.0: output 'corrected' changes to arflex.JointRef 1.0 stream, but its peer "
                + "robot.joint_ref (updated by the set) reads arflex.JointRef 1.0 state (method stream is not state)"),
                check(List.of(), List.of(c2, r1)));
    }

    @Test
    void aNewComponentsExplicitBindingIsCheckedAgainstItsPeer() throws Exception {
        Contract mon = contract("mon", "1.0.0", null, "<in name=\"ref\" type=\"arflex.JointRef\" typeVersion=\"1.0\" "
                + "method=\"stream\"><bind component=\"corr\" port=\"corrected\"/></in>");
        assertEquals(List.of("install mon 1.0.0: input 'ref' (arflex.JointRef 1.0 stream) names its peer corr.corrected, "
                + "which writes arflex.JointRef 1.0 state (method state is not stream)"), check(List.of(mon), List.of()));
        Contract missing = contract("mon", "1.0.0", null, "<in name=\"ref\" type=\"arflex.JointRef\" typeVersion=\"1.0\" "
                + "method=\"state\"><bind component=\"corr\" port=\"nothing\"/></in>");
        assertEquals(List.of("install mon 1.0.0: input 'ref' (arflex.JointRef 1.0 state) names its peer corr.nothing, "
                + "but corr 1.0.0 has no output 'nothing'"), check(List.of(missing), List.of()));
        Contract ok = contract("mon", "1.0.0", null, "<in name=\"ref\" type=\"arflex.JointRef\" typeVersion=\"1.0\" "
                + "method=\"state\"><bind component=\"corr\" port=\"corrected\"/></in>");
        assertEquals(List.of(), check(List.of(ok), List.of()));
    }

    @Test
    void aNewComponentsRequiredInputNeedsAProviderInItsFormatAmongItsTypesPeers() throws Exception {
        Contract mon = contract("mon", "1.0.0", null, "<in name=\"ref\" type=\"arflex.JointRef\" typeVersion=\"1.0\" "
                + "method=\"stream\"><bind filter=\"(role=correction)\"/></in>");
        assertEquals(List.of("install mon 1.0.0: input 'ref' (arflex.JointRef 1.0 stream) has no provider in its format; "
                + "its peers of that type: corr.corrected writes arflex.JointRef 1.0 state (method state is not stream)"),
                check(List.of(mon), List.of()));
        Contract optional = contract("mon", "1.0.0", null, "<in name=\"ref\" type=\"arflex.JointRef\" typeVersion=\"1.0\" "
                + "method=\"stream\" optional=\"true\"><bind filter=\"(role=correction)\"/></in>");
        assertEquals(List.of(), check(List.of(optional), List.of()), "an optional input may stay unbound");
        Contract ofNone = contract("mon", "1.0.0", null, "<in name=\"w\" type=\"arflex.Wrench\" typeVersion=\"1.0\" "
                + "method=\"stream\"/>");
        assertEquals(List.of(), check(List.of(ofNone), List.of()), "no peer of that type: the planner says no provider");
        Contract byType = contract("mon", "1.0.0", null, "<in name=\"ref\" type=\"arflex.JointRef\" typeVersion=\"1.0\" "
                + "method=\"state\"/>");
        assertEquals(List.of(), check(List.of(byType), List.of()), "a provider in its format exists");
    }

    @Test
    void aRunningConsumerThatNamesANewComponentsOutputReadsItsFormat() throws Exception {
        Contract waiting = contract("panel", "1.0.0", null, "<in name=\"t\" type=\"arflex.Sample\" typeVersion=\"1.0\" "
                + "method=\"state\" optional=\"true\"><bind component=\"gauge\" port=\"value\"/></in>");
        Contract gauge = contract("gauge", "1.0.0", null,
                "<out name=\"value\" type=\"arflex.Sample\" typeVersion=\"1.0\" method=\"stream\" depth=\"4\"/>");
        assertEquals(List.of("install gauge 1.0.0: output 'value' is arflex.Sample 1.0 stream, but its peer panel.t names "
                + "it and reads arflex.Sample 1.0 state (method stream is not state)"),
                formats.check(List.of(traj, corr, robot, waiting), wires, List.of(gauge), List.of()));
    }

    @Test
    void aComponentTheSetUninstallsIsNoPeer() throws Exception {
        // corr 2.0.0 writes a stream, but its only reader, robot, is uninstalled by the same set
        Contract stream = contract("corr", "2.0.0", "correction", REF_IN
                + "<out name=\"corrected\" type=\"arflex.JointRef\" typeVersion=\"1.0\" method=\"stream\" depth=\"8\"/>");
        assertEquals(1, check(List.of(), List.of(stream)).size(), "refused while robot reads it");
        assertEquals(List.of(), formats.check(List.of(traj, corr, robot), wires, List.of(), List.of(stream),
                java.util.Set.of("robot")));
        // a new component naming an uninstalled peer is told so
        Contract mon = contract("mon", "1.0.0", null, "<in name=\"ref\" type=\"arflex.JointRef\" typeVersion=\"1.0\" "
                + "method=\"state\"><bind component=\"corr\" port=\"corrected\"/></in>");
        assertEquals(List.of(), check(List.of(mon), List.of()));
        assertEquals(List.of("install mon 1.0.0: input 'ref' (arflex.JointRef 1.0 state) names its peer corr.corrected, "
                + "but the set uninstalls corr"), formats.check(List.of(traj, corr, robot), wires, List.of(mon), List.of(),
                java.util.Set.of("corr")));
        // a required input by type: an uninstalled provider in another format is not listed as a peer
        Contract byType = contract("mon", "1.0.0", null, "<in name=\"ref\" type=\"arflex.JointRef\" typeVersion=\"1.0\" "
                + "method=\"stream\"/>");
        List<String> p = formats.check(List.of(traj, corr, robot), wires, List.of(byType), List.of(), java.util.Set.of("corr"));
        assertEquals(1, p.size(), p::toString);
        assertTrue(p.get(0).contains("traj.joint_ref writes") && !p.get(0).contains("corr.corrected"), p.get(0));
    }
}
