package org.arflex.drcr.impl.services;

import static org.junit.jupiter.api.Assertions.assertEquals;

import java.net.URI;
import java.nio.charset.StandardCharsets;
import java.util.List;
import org.arflex.contract.Contract;
import org.arflex.contract.ContractParser;
import org.arflex.contract.PortTypes;
import org.junit.jupiter.api.Test;

/**
 * The uninstalls and parameter writes of a deployment set (D50), read from a descriptor and
 * checked against a cell of two running components, before anything is installed.
 */
class DeploymentChangesTest {

    static Contract contract(String name, String version, String properties) throws Exception {
        return ContractParser.create(PortTypes.builtin()).parse("<component xmlns=\"urn:arflex:contract:1\" name=\"" + name
                + "\" version=\"" + version + "\"><implementation executable=\"" + name
                + "\" task=\"periodic\" movesHardware=\"false\"/>"
                + "<ports><out name=\"y\" type=\"arflex.Sample\" typeVersion=\"1.0\" method=\"state\"/></ports>"
                + "<properties>" + properties + "</properties>"
                + "<timing period=\"1ms\" deadline=\"1ms\" wcet=\"50us\" priority=\"80\"/>"
                + "<resources memory=\"1MiB\" network=\"0\"/><criticality>5</criticality>"
                + "<fault restart=\"permanent\" intensity=\"2\" window=\"10s\" backoff=\"100ms\" safe=\"hold\""
                + " heartbeatTimeout=\"100ms\"/></component>", name + ".xml");
    }

    static final String GAIN = "<property name=\"gain\" type=\"double\" default=\"0.5\" min=\"0\" max=\"1\" mutable=\"true\">g</property>";
    static final String MODE = "<property name=\"mode\" type=\"int\" default=\"1\" min=\"0\" max=\"3\" mutable=\"false\">m</property>";

    private final Contract counter = contract("counter", "1.0.0", GAIN + MODE);
    private final Contract scaler = contract("scaler", "1.0.0", GAIN);

    DeploymentChangesTest() throws Exception {
    }

    private static List<DeploymentDescriptor.Entry> changes(String body) {
        return DeploymentDescriptor.parse((DeploymentDescriptorTest.HEAD + body + "\n</deployment>\n")
                .getBytes(StandardCharsets.UTF_8), URI.create("file:/srv/sets/cell-2.xml")).changes();
    }

    private List<String> check(String body, List<Contract> installs, List<Contract> updates) {
        return DeploymentChanges.check(changes(body), List.of(counter, scaler), installs, updates);
    }

    @Test
    void uninstallsAndWritesOfRunningNewAndUpdatedComponentsPass() throws Exception {
        Contract fresh = contract("fresh", "1.0.0", MODE);
        Contract counter2 = contract("counter", "1.1.0", GAIN + MODE);
        assertEquals(List.of(), check("<uninstall component=\"scaler\"/>\n"
                + "<set component=\"counter\" parameter=\"gain\" value=\"0.25\"/>\n"
                + "<set component=\"fresh\" parameter=\"mode\" value=\"2\"/>", List.of(fresh), List.of()));
        // an immutable parameter of an updated component: its new half starts with it
        assertEquals(List.of(), check("<set component=\"counter\" parameter=\"mode\" value=\"3\"/>", List.of(),
                List.of(counter2)));
    }

    @Test
    void eachBadUninstallOrWriteIsNamedWithItsLine() throws Exception {
        Contract fresh = contract("fresh", "1.0.0", MODE);
        assertEquals(List.of("line 2, uninstall ghost: 'ghost' is not running"),
                check("<uninstall component=\"ghost\"/>", List.of(), List.of()));
        assertEquals(List.of("line 2, uninstall fresh: 'fresh' is also installed by the set"),
                check("<uninstall component=\"fresh\"/>", List.of(fresh), List.of()));
        assertEquals(List.of("line 3, set scaler gain 0.5: 'scaler' is uninstalled by the set"),
                check("<uninstall component=\"scaler\"/>\n<set component=\"scaler\" parameter=\"gain\" value=\"0.5\"/>",
                        List.of(), List.of()));
        assertEquals(List.of("line 2, set ghost gain 1: no component 'ghost' runs or is installed by the set"),
                check("<set component=\"ghost\" parameter=\"gain\" value=\"1\"/>", List.of(), List.of()));
        assertEquals(List.of("line 2, set scaler gian 1: scaler 1.0.0 has no parameter 'gian' (has [gain])"),
                check("<set component=\"scaler\" parameter=\"gian\" value=\"1\"/>", List.of(), List.of()));
        assertEquals(List.of("line 2, set counter gain 1.5: counter.gain: 1.5 is out of range [0.0, 1.0]"),
                check("<set component=\"counter\" parameter=\"gain\" value=\"1.5\"/>", List.of(), List.of()));
        assertEquals(List.of("line 2, set counter mode two: counter.mode: 'two' is not an integer"),
                check("<set component=\"counter\" parameter=\"mode\" value=\"two\"/>", List.of(), List.of()));
        assertEquals(List.of("line 2, set counter mode 2: counter.mode is immutable while it runs (mutable=false)"),
                check("<set component=\"counter\" parameter=\"mode\" value=\"2\"/>", List.of(), List.of()));
        // a new component's contract is the one checked
        assertEquals(List.of("line 2, set fresh gain 0.5: fresh 1.0.0 has no parameter 'gain' (has [mode])"),
                check("<set component=\"fresh\" parameter=\"gain\" value=\"0.5\"/>", List.of(fresh), List.of()));
    }
}
