package org.arflex.drcr.impl.runtime;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.ByteArrayInputStream;
import java.nio.charset.StandardCharsets;
import java.util.HashMap;
import java.util.List;
import java.util.Map;
import org.arflex.contract.PortTypes;
import org.junit.jupiter.api.Test;

/** The extender's contract reading: a bad contract is reported with its place and skipped; the others still load. */
class ContractReaderTest {

    private final Map<String, byte[]> entries = new HashMap<>();

    private ContractReader.Result read(String header) {
        return new ContractReader(PortTypes.builtin()).read("bundle 9 (x)", header, p -> {
            byte[] b = entries.get(p);
            return b == null ? null : new ByteArrayInputStream(b);
        });
    }

    private void put(String path, String text) {
        entries.put(path, text.getBytes(StandardCharsets.UTF_8));
    }

    @Test
    void goodBadAndMissingContractsEachGetTheirOwnResult() {
        put("OSGI-INF/arflex/a.xml", CellTest.contract("a", CellTest.PROVIDER_PORTS, CellTest.PERMANENT, false, 1, "50us"));
        put("native/linux-x86_64/a", "#!");
        put("OSGI-INF/arflex/b.xml", CellTest.contract("b", CellTest.PROVIDER_PORTS, CellTest.PERMANENT, false, 1, "50us")
                .replace("<criticality>1</criticality>", "<criticality>high</criticality>"));
        put("native/linux-x86_64/b", "#!");
        put("OSGI-INF/arflex/c.xml", CellTest.contract("c", CellTest.PROVIDER_PORTS, CellTest.PERMANENT, false, 1, "50us"));
        put("OSGI-INF/arflex/e.xml", "<?xml version=\"1.0\"?><!DOCTYPE x [<!ENTITY e SYSTEM \"file:///etc/passwd\">]><component>&e;</component>");
        ContractReader.Result r = read("OSGI-INF/arflex/a.xml, /OSGI-INF/arflex/b.xml,OSGI-INF/arflex/c.xml,"
                + "OSGI-INF/arflex/d.xml,OSGI-INF/arflex/e.xml");
        assertEquals(List.of("a"), r.contracts().stream().map(c -> c.name()).toList());
        assertEquals(4, r.problems().size(), r.problems().toString());
        String all = String.join("\n", r.problems());
        assertTrue(all.contains("bundle 9 (x) OSGI-INF/arflex/b.xml:1:"), all);
        assertTrue(all.contains("criticality"), all);
        assertTrue(all.contains("native/linux-x86_64/c is missing"), all);
        assertTrue(all.contains("OSGI-INF/arflex/d.xml: contract named in ARFLEX-Contract is missing"), all);
        assertTrue(all.contains("e.xml"), all);
        assertTrue(!all.contains("root:"), "an external entity must never be expanded: " + all);
    }

    @Test
    void headerPathsAreTrimmedAndRelative() {
        assertEquals(List.of("a.xml", "b/c.xml"), ContractReader.paths(" /a.xml , b/c.xml,, "));
        assertEquals(List.of(), ContractReader.paths(null));
    }
}
