package org.arflex.contract;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.io.InputStream;
import java.nio.charset.StandardCharsets;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import org.junit.jupiter.api.Test;

class ContractParserTest {
    private static final ContractParser PARSER = ContractParser.create();

    static String resource(String path) throws IOException {
        try (InputStream in = ContractParserTest.class.getResourceAsStream(path)) {
            if (in == null) {
                throw new IOException("missing test resource " + path);
            }
            return new String(in.readAllBytes(), StandardCharsets.UTF_8);
        }
    }

    @Test
    void parsesTheSpecExample() throws Exception {
        Contract c = PARSER.parse(resource("/good/sample-scaler.xml"), "sample-scaler.xml");
        assertEquals("sample-scaler", c.name());
        assertEquals(Contract.TaskType.PERIODIC, c.taskType());
        assertEquals(1_000_000L, c.timing().periodNs());
        assertEquals(50_000L, c.timing().wcetNs());
        assertEquals(List.of(1), c.timing().cpus());
        assertEquals(8L << 20, c.resources().memoryBytes());
        assertEquals("filter", c.attributes().get("role"));
        PortSpec x = c.port("x").orElseThrow();
        assertEquals(Binding.explicit("sample-counter", "count"), x.binding().orElseThrow());
        PortSpec y = c.port("y").orElseThrow();
        assertEquals(64, y.depth());
        assertEquals(PortSpec.Method.STREAM, y.method());
        assertEquals(2.0, c.property("gain").orElseThrow().defaultValue().asDouble());
        assertEquals(FaultPolicy.Restart.PERMANENT, c.fault().restart());
        assertEquals(10_000L, c.fault().windowMs());
        assertTrue(c.update().isPresent());
        assertEquals("sample-scaler.xml", c.source());
    }

    @Test
    void writerRoundTrips() throws Exception {
        Contract c = PARSER.parse(resource("/good/sample-scaler.xml"), "a.xml");
        String xml = ContractWriter.create().write(c);
        Contract back = PARSER.parse(xml, "a.xml");
        assertEquals(c, back);
    }

    @Test
    void problemsNameFileLineColumnSectionAndField() throws Exception {
        String bad = resource("/good/sample-scaler.xml").replace("wcet=\"50us\"", "wcet=\"5ms\"");
        ContractException e = assertThrows(ContractException.class, () -> PARSER.parse(bad, "s.xml"));
        assertEquals(1, e.problems().size());
        Problem p = e.problems().get(0);
        assertEquals("s.xml", p.source());
        assertEquals(17, p.line());
        assertEquals("8.2", p.section());
        assertEquals("timing/@wcet", p.field());
        assertTrue(p.toString().startsWith("s.xml:17:3: [§8.2] timing/@wcet: impossible timing"), p.toString());
    }

    @Test
    void validateNeverThrows() {
        assertFalse(PARSER.validate("", "empty.xml").isEmpty());
        assertFalse(PARSER.validate("<<<", "junk.xml").isEmpty());
        assertFalse(PARSER.validate(null, "null.xml").isEmpty());
    }

    @Test
    void parseAllIsolatesOneBadContractAmongGoodOnes() throws Exception {
        String good = resource("/good/sample-scaler.xml");
        Map<String, String> docs = new LinkedHashMap<>();
        docs.put("one.xml", good);
        docs.put("bad.xml", good.replace("priority=\"80\"", "priority=\"99\""));
        docs.put("two.xml", good.replace("name=\"sample-scaler\"", "name=\"sample-scaler-2\""));
        List<ContractParser.Result> r = PARSER.parseAll(docs);
        assertEquals(3, r.size());
        assertTrue(r.get(0).ok());
        assertFalse(r.get(1).ok());
        assertEquals("8.3", r.get(1).problems().get(0).section());
        assertTrue(r.get(2).ok());
        assertEquals("sample-scaler-2", r.get(2).contract().orElseThrow().name());
    }
}
