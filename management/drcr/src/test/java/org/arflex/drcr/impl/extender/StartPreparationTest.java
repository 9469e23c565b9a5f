package org.arflex.drcr.impl.extender;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertTrue;
import java.io.IOException;
import java.lang.reflect.Proxy;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import org.arflex.contract.Contract;
import org.arflex.contract.ContractParser;
import org.arflex.contract.PortTypes;
import org.junit.jupiter.api.Test;
import org.osgi.framework.Bundle;
import org.osgi.framework.Version;

/**
 * D54: an installed contract bundle has its executables extracted ahead of its start, only while nothing makes that copy wrong: the gate refuses nothing, the revision is the
 * one read, the bundle is not started yet. The first start takes the copy, later ones extract.
 */
class StartPreparationTest {

    private final List<Runnable> queued = new ArrayList<>();
    private final List<String> extracted = new ArrayList<>();
    private final List<String> log = new ArrayList<>();
    private int state = Bundle.INSTALLED;
    private String refusal;
    private boolean extractionFails;

    private final Bundle bundle = (Bundle) Proxy.newProxyInstance(Bundle.class.getClassLoader(),
            new Class<?>[] {Bundle.class}, (p, m, a) -> switch (m.getName()) {
                case "getState" -> state;
                case "getBundleId" -> 7L;
                case "getSymbolicName" -> "org.example.counter";
                case "getVersion" -> Version.parseVersion("1.0.0");
                default -> throw new UnsupportedOperationException(m.getName());
            });

    private final StartPreparation prep = new StartPreparation(queued::add, b -> refusal, (b, exe) -> {
        if (extractionFails) {
            throw new IOException("disk full");
        }
        extracted.add(exe);
        return Path.of("/data/7/" + exe);
    }, log::add);

    private static Contract contract(String name) throws Exception {
        String xml = """
            <?xml version="1.0" encoding="UTF-8"?>
            <component xmlns="urn:arflex:contract:1" name="NAME" version="1.0.0">
              <implementation executable="NAME-rt" task="periodic" movesHardware="false"/>
              <ports><out name="count" type="arflex.Sample" typeVersion="1.0" method="state"/></ports>
              <timing period="10ms" deadline="10ms" wcet="200us" priority="50"/>
              <resources memory="8MiB" network="0"/>
              <criticality>5</criticality>
              <fault restart="permanent" intensity="3" window="10s" backoff="100ms" safe="hold" heartbeatTimeout="1s"/>
            </component>
            """.replace("NAME", name);
        return ContractParser.create(PortTypes.builtin()).parse(xml, name + ".xml");
    }

    private ContractExtender.Tracked tracked(String... names) throws Exception {
        ContractExtender.Tracked t = new ContractExtender.Tracked();
        List<Contract> cs = new ArrayList<>();
        for (String n : names) {
            cs.add(contract(n));
        }
        t.contracts = cs;
        return t;
    }

    private void runQueued() {
        List<Runnable> now = new ArrayList<>(queued);
        queued.clear();
        now.forEach(Runnable::run);
    }

    @Test
    void anInstalledBundleHasItsExecutablesExtractedOnceForItsFirstStart() throws Exception {
        ContractExtender.Tracked t = tracked("a", "b");
        prep.submit(bundle, t);
        assertTrue(extracted.isEmpty(), "nothing on the framework's thread");
        runQueued();
        assertEquals(List.of("a-rt", "b-rt"), extracted);
        assertEquals(2, t.extracted.size(), "recorded for release at update or uninstall");
        assertEquals(Path.of("/data/7/a-rt"), StartPreparation.take(t, "a-rt"));
        assertNull(StartPreparation.take(t, "a-rt"), "a later start extracts afresh");
        assertTrue(log.stream().anyMatch(l -> l.contains("bundle 7 (org.example.counter 1.0.0): prepared for its start")), log.toString());
    }

    @Test
    void aBundleTheGateRefusesHasNothingExtracted() throws Exception {
        refusal = "bundle 7 is not from a trusted folder";
        ContractExtender.Tracked t = tracked("a");
        prep.submit(bundle, t);
        runQueued();
        assertTrue(extracted.isEmpty());
        assertTrue(t.prepared.isEmpty() && t.extracted.isEmpty());
    }

    @Test
    void aRevisionGoneBeforeThePreparationRanExtractsNothing() throws Exception {
        ContractExtender.Tracked t = tracked("a");
        prep.submit(bundle, t);
        synchronized (t) {
            StartPreparation.drop(t); // the bundle was updated (or uninstalled) meanwhile
        }
        runQueued();
        assertTrue(extracted.isEmpty());
        assertNull(StartPreparation.take(t, "a-rt"));
    }

    @Test
    void aBundleStartedBeforeThePreparationRanIsLeftToItsStart() throws Exception {
        ContractExtender.Tracked t = tracked("a");
        prep.submit(bundle, t);
        state = Bundle.ACTIVE;
        runQueued();
        assertTrue(extracted.isEmpty());
    }

    @Test
    void aBundleAlreadyStartingOrWithoutContractsIsNotPrepared() throws Exception {
        state = Bundle.STARTING;
        prep.submit(bundle, tracked("a"));
        state = Bundle.INSTALLED;
        prep.submit(bundle, tracked());
        assertTrue(queued.isEmpty());
    }

    @Test
    void aFailedExtractionIsLoggedAndLeftToTheStart() throws Exception {
        extractionFails = true;
        ContractExtender.Tracked t = tracked("a");
        prep.submit(bundle, t);
        runQueued();
        assertTrue(t.prepared.isEmpty());
        assertTrue(log.stream().anyMatch(l -> l.contains("not prepared ahead of its start (disk full); the start does it")),
                log.toString());
    }
}
