package org.arflex.contract;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.ByteArrayInputStream;
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
    void stateBlockIsReadWithItsConversionsAndSaysWhatItAdopts() throws Exception {
        Contract c = PARSER.parse(resource("/good/state-block.xml"), "state-block.xml");
        StateSpec st = c.state().orElseThrow();
        assertEquals("arflex.TrajectoryState", st.type());
        assertEquals(new TypeVersion(1, 0), st.typeVersion());
        assertEquals(List.of(new StateSpec.From("arflex.TrajectoryState", new TypeVersion(0, 9)),
                new StateSpec.From("arflex.JointRef", new TypeVersion(1, 0))), st.convertsFrom());
        assertTrue(st.adopts("arflex.TrajectoryState", new TypeVersion(1, 0)));
        assertTrue(st.adopts("arflex.TrajectoryState", new TypeVersion(1, 2)), "a later minor feeds 1.0 (SPEC 13.4)");
        assertTrue(st.adopts("arflex.TrajectoryState", new TypeVersion(0, 9)), "declared conversion");
        assertTrue(st.adopts("arflex.JointRef", new TypeVersion(1, 0)), "declared conversion of another type");
        assertFalse(st.adopts("arflex.TrajectoryState", new TypeVersion(2, 0)), "another major, no conversion");
        assertFalse(st.adopts("arflex.TcpCorrectionState", new TypeVersion(1, 0)), "another type, no conversion");
        assertEquals(c, PARSER.parse(ContractWriter.create().write(c), "state-block.xml"), "the writer keeps it");
        assertTrue(PARSER.parse(resource("/good/sample-scaler.xml"), "s.xml").state().isEmpty());
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

    /**
     * Failures before the first token (no input, an unsupported or undetectable encoding) are
     * reported by Woodstox without a location or at column 0; they are at the document's start,
     * 1:1 (issue 16, found by ContractFuzzTest; corpus files finding-*-no-location).
     */
    @Test
    void failuresBeforeTheFirstTokenAreLocatedAtTheStart() throws Exception {
        Map<String, byte[]> docs = new LinkedHashMap<>();
        docs.put("empty", new byte[0]);
        docs.put("utf-9", "<?xml version=\"1.0\" encoding=\"UTF-9\"?>\n<component xmlns=\"urn:arflex:contract:1\"/>"
                .getBytes(StandardCharsets.US_ASCII));
        docs.put("ucs-4 3412", new byte[] {0, '<', 0, 0, 0, 0, 0, 0});
        for (Map.Entry<String, byte[]> d : docs.entrySet()) {
            ContractException e = assertThrows(ContractException.class,
                    () -> PARSER.parse(new ByteArrayInputStream(d.getValue()), "start.xml"), d.getKey());
            Problem p = e.problems().get(0);
            assertEquals("2.1", p.section(), d.getKey());
            assertEquals(1, p.line(), d.getKey() + ": " + p);
            assertEquals(1, p.column(), d.getKey() + ": " + p);
        }
        ContractException e = assertThrows(ContractException.class, () -> PortTypes.parse(new ByteArrayInputStream(
                "<?xml version=\"1.0\" encoding=\"UTF-%\"?><portType xmlns=\"urn:arflex:porttype:1\"/>"
                        .getBytes(StandardCharsets.US_ASCII)), "t.xml"));
        assertEquals("t.xml:1:1: [§2.1] (document): malformed XML: Unsupported encoding: UTF-%",
                e.problems().get(0).toString());
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

    @Test
    void inputLargerThanOneMebibyteIsRefusedBeforeParsing() throws Exception {
        String good = resource("/good/sample-scaler.xml");
        String big = good.replace("<description>", "<description>" + "x".repeat(ContractParser.MAX_BYTES));
        List<Problem> p = PARSER.validate(big, "big.xml");
        assertEquals(1, p.size());
        assertEquals("2.1", p.get(0).section());
        assertTrue(p.get(0).message().contains("larger than 1048576 bytes"), p.get(0).message());
    }

    @Test
    void tooManyElementsHitTheElementLimit() throws Exception {
        String good = resource("/good/sample-scaler.xml");
        String many = good.replace("</attributes>", "<attribute name=\"a\" value=\"b\"/>".repeat(10_001) + "</attributes>");
        List<Problem> p = PARSER.validate(many, "many.xml");
        assertEquals(1, p.size(), p.toString());
        assertEquals("2.1", p.get(0).section());
        assertTrue(p.get(0).message().contains("limit"), p.get(0).message());
    }

    @Test
    void longTextNodeHitsTheTextLimit() throws Exception {
        String good = resource("/good/sample-scaler.xml");
        String longText = good.replace("<description>", "<description>" + "y".repeat(70_000));
        List<Problem> p = PARSER.validate(longText, "long.xml");
        assertEquals("2.1", p.get(0).section(), p.toString());
    }

    @Test
    void exclusiveCpuIsParsedWrittenAndDefaultsToShared() throws Exception {
        Contract probe = PARSER.parse(resource("/good/latency-probe.xml"), "latency-probe.xml");
        assertTrue(probe.timing().exclusive());
        assertEquals(List.of(1), probe.timing().cpus());
        String written = ContractWriter.create().write(probe);
        assertTrue(written.contains("exclusive=\"true\""), written);
        assertEquals(probe, PARSER.parse(written, "latency-probe.xml"));
        Contract shared = PARSER.parse(resource("/good/sample-scaler.xml"), "sample-scaler.xml");
        assertFalse(shared.timing().exclusive());
        assertFalse(ContractWriter.create().write(shared).contains("exclusive"));
        assertEquals(new Timing(1, 1, 1, 1, List.of(0)), new Timing(1, 1, 1, 1, List.of(0), false));
    }

    @Test
    void serviceWithoutTimingGetsZeroTimingAndRoundTrips() throws Exception {
        Contract c = PARSER.parse(resource("/good/debug-monitor.xml"), "debug-monitor.xml");
        assertEquals(Contract.TaskType.SERVICE, c.taskType());
        assertEquals(new Timing(0, 0, 0, 0, List.of()), c.timing());
        assertEquals(10L * 1024, c.resources().networkBps());
        assertEquals(c, PARSER.parse(ContractWriter.create().write(c), "debug-monitor.xml"));
    }

    @Test
    void deadlineDefaultsToPeriodAndCpuListsExpand() throws Exception {
        Contract c = PARSER.parse(resource("/good/joint-trajectory.xml"), "jt.xml");
        assertEquals(c.timing().periodNs(), c.timing().deadlineNs());
        assertEquals(List.of(0, 2, 3), c.timing().cpus());
        assertEquals(1_000_000L, c.resources().networkBps());
        assertEquals("Interpolates joint targets into a 1 kHz joint reference.", c.description());
        assertEquals(Binding.filter("(&(role=robot)(|(sim=true)(sim=false))(!(degraded=*)))"),
                c.port("state").orElseThrow().binding().orElseThrow());
        assertTrue(c.port("safety").orElseThrow().optional());
        assertEquals(PortSpec.Overflow.DROP_NEWEST, c.port("log").orElseThrow().overflow());
        assertEquals(PropertySpec.Value.ofInt(6), c.property("axes").orElseThrow().defaultValue());
        assertEquals(PropertySpec.Value.ofBool(false), c.property("dry_run").orElseThrow().defaultValue());
        assertEquals(0.001, c.property("blend.radius").orElseThrow().defaultValue().asDouble());
        assertEquals(FaultPolicy.SafeOutput.ZERO, c.fault().safeOutput());
        assertEquals(3, c.fault().intensity());
        assertEquals(List.of("state", "safety"), c.inputs().stream().map(PortSpec::name).toList());
    }

    @Test
    void orphanHoldDefaultsToTwoSecondsAndIsParsedAndWritten() throws Exception {
        String xml = resource("/good/sample-scaler.xml");
        Contract c = PARSER.parse(xml, "s.xml");
        assertEquals(2_000L, c.fault().orphanHoldMs());
        for (var e : Map.of("500ms", 500L, "0ms", 0L, "0s", 0L, "60s", 60_000L).entrySet()) {
            Contract h = PARSER.parse(xml.replace("heartbeatTimeout=\"100ms\"",
                    "heartbeatTimeout=\"100ms\" orphanHold=\"" + e.getKey() + "\""), "s.xml");
            assertEquals(e.getValue(), h.fault().orphanHoldMs(), e.getKey());
            assertEquals(h, PARSER.parse(ContractWriter.create().write(h), "s.xml"), "round trip " + e.getKey());
        }
        for (var e : Map.of("61s", "out of range", "1500us", "whole number of milliseconds",
                "2 s", "not a duration").entrySet()) {
            List<Problem> p = PARSER.validate(xml.replace("heartbeatTimeout=\"100ms\"",
                    "heartbeatTimeout=\"100ms\" orphanHold=\"" + e.getKey() + "\""), "s.xml");
            assertTrue(p.stream().anyMatch(x -> x.field().equals("fault/@orphanHold") && x.message().contains(e.getValue())),
                    e.getKey() + ": " + p);
        }
    }

    @Test
    void sha256IsNormalisedToLowerCase() throws Exception {
        Contract c = PARSER.parse(resource("/good/camera.xml"), "camera.xml");
        assertEquals("e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855", c.update().orElseThrow().sha256());
        assertEquals("https", c.update().orElseThrow().url().getScheme());
    }

    @Test
    void unknownPortTypeWithACustomRegistryIsKnown() throws Exception {
        String xml = resource("/good/sample-scaler.xml");
        ContractParser noTypes = ContractParser.create(PortTypes.of(List.of()));
        List<Problem> p = noTypes.validate(xml, "s.xml");
        assertEquals(2, p.size(), p.toString());
        assertTrue(p.stream().allMatch(x -> x.section().equals("6.2")));
    }

    @Test
    void predefinedEntitiesAndCharacterReferencesStillWork() throws Exception {
        String xml = resource("/good/sample-scaler.xml").replace("Multiplies every sample by a gain.",
                "R&amp;D &lt;scaler&gt; &#x263A; &quot;q&quot; &apos;a&apos;");
        Contract c = PARSER.parse(xml, "s.xml");
        assertEquals("R&D <scaler> \u263A \"q\" 'a'", c.description());
        assertEquals(c, PARSER.parse(ContractWriter.create().write(c), "s.xml"));
    }

    @Test
    void portsKeepDocumentOrderAcrossInAndOutAndEmptyContainersAreEmpty() throws Exception {
        String good = resource("/good/sample-scaler.xml");
        String xml = good.replace("<out name=\"y\"",
                "<in name=\"z\" type=\"arflex.Sample\" typeVersion=\"1.0\" method=\"state\"/>\n<out name=\"y\"")
                .replace("</ports>", "<in name=\"w\" type=\"arflex.Sample\" typeVersion=\"1.0\" method=\"state\"/></ports>");
        Contract c = PARSER.parse(xml, "o.xml");
        assertEquals(List.of("x", "z", "y", "w"), c.ports().stream().map(PortSpec::name).toList());
        assertEquals(List.of("x", "z", "w"), c.inputs().stream().map(PortSpec::name).toList());
        String empty = good.replaceAll("(?s)<ports>.*</ports>", "<ports/>")
                .replaceAll("(?s)<properties>.*</properties>", "<properties></properties>")
                .replaceAll("(?s)<attributes>.*</attributes>", "<attributes>\n  </attributes>")
                .replace("<description>Multiplies every sample by a gain.</description>", "<description/>");
        Contract e = PARSER.parse(empty, "e.xml");
        assertTrue(e.ports().isEmpty());
        assertTrue(e.properties().isEmpty());
        assertTrue(e.attributes().isEmpty());
        assertEquals("", e.description());
    }

    @Test
    void aRolloutDeclaresTheShadowRunTheWindowTolerancesAndEnvelopes() throws Exception {
        Contract c = PARSER.parse(resource("/good/rollout.xml"), "rollout.xml");
        RolloutSpec r = c.rollout().orElseThrow();
        assertEquals(200, r.shadow().getAsLong());
        assertEquals(1000, r.window().getAsLong());
        assertEquals(java.util.List.of(new RolloutSpec.Tolerance("y", "value", 0.001)), r.tolerances());
        assertEquals(java.util.List.of(new RolloutSpec.Envelope("y", "value", -20, 20)), r.envelopes());
        // none declared: empty, and the shadow run and window default where they are used
        assertTrue(PARSER.parse(resource("/good/sample-scaler.xml"), "s.xml").rollout().isEmpty());
        Contract bare = PARSER.parse(resource("/good/sample-scaler.xml").replace("</component>",
                "<rollout shadow=\"5\"/></component>"), "s.xml");
        assertEquals(5, bare.rollout().orElseThrow().shadow().getAsLong());
        assertTrue(bare.rollout().orElseThrow().window().isEmpty());
        // a second tolerance of the same field is named
        ContractException e = assertThrows(ContractException.class, () -> PARSER.parse(resource("/good/rollout.xml")
                .replace("<envelope", "<tolerance port=\"y\" field=\"value\" abs=\"2\"/><envelope"), "r.xml"));
        assertTrue(e.getMessage().contains("[§12.2] rollout/tolerance[y.value]: a second tolerance for y.value"),
                e.getMessage());
    }
}
