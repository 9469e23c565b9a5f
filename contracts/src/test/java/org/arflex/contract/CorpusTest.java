package org.arflex.contract;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;
import static org.junit.jupiter.api.Assertions.fail;

import java.io.IOException;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.Map;
import java.util.stream.Stream;
import org.junit.jupiter.api.io.TempDir;
import org.junit.jupiter.params.ParameterizedTest;
import org.junit.jupiter.params.provider.Arguments;
import org.junit.jupiter.params.provider.MethodSource;
import org.junit.jupiter.api.Test;

/**
 * The contract corpus: every file in src/test/resources/bad must be refused with the problems
 * its .expected file names (one per line: {@code section|field|message fragment}); every file in
 * good/ must parse, pass the XSD and round-trip through the writer.
 */
class CorpusTest {
    private static final Path RESOURCES = Path.of("src/test/resources").toAbsolutePath();
    private static final ContractParser PARSER = ContractParser.create();

    static Stream<String> bad() throws IOException {
        return list("bad");
    }

    static Stream<String> good() throws IOException {
        return list("good");
    }

    private static Stream<String> list(String dir) throws IOException {
        try (Stream<Path> s = Files.list(RESOURCES.resolve(dir))) {
            List<String> names = s.map(p -> p.getFileName().toString()).filter(n -> n.endsWith(".xml")).sorted().toList();
            return names.stream();
        }
    }

    @ParameterizedTest(name = "bad/{0}")
    @MethodSource("bad")
    void badContractIsRefusedWithItsExpectedProblems(String file) throws IOException {
        Path xml = RESOURCES.resolve("bad").resolve(file);
        Path exp = RESOURCES.resolve("bad").resolve(file.replace(".xml", ".expected"));
        assertTrue(Files.exists(exp), "missing " + exp);
        assertRefusedWith(xml, Files.readAllLines(exp, StandardCharsets.UTF_8));
    }

    /**
     * Hostile documents too large to keep in bad/ (a text node over 100,000 characters in a
     * document under 1 MiB), made at test time: each must be refused with a located §2.1
     * problem, never with an exception escaping the parser (issue 16, finding 7: Woodstox's
     * unchecked WstxLazyException escaped).
     */
    @ParameterizedTest(name = "generated/{0}")
    @MethodSource("hugeText")
    void hugeTextIsRefusedWithALocatedProblem(String name, String xml, @TempDir Path dir) throws IOException {
        assertTrue(xml.getBytes(StandardCharsets.UTF_8).length < ContractParser.MAX_BYTES, "must pass the size cap");
        Path file = dir.resolve(name + ".xml");
        Files.writeString(file, xml, StandardCharsets.UTF_8);
        List<Problem> problems = assertRefusedWith(file, List.of("2.1|(document)|parser limit"));
        assertTrue(problems.stream().allMatch(p -> p.column() > 0), "problem without a column: " + problems);

        ContractException e = assertThrows(ContractException.class, () -> PARSER.parse(xml, name));
        assertEquals("2.1", e.problems().get(0).section());
        List<Problem> validated = PARSER.validate(xml, name);
        assertFalse(validated.isEmpty());
        assertTrue(validated.get(0).line() > 0, validated.toString());
        List<ContractParser.Result> all = PARSER.parseAll(Map.of(name, xml));
        assertFalse(all.get(0).ok());
    }

    static Stream<Arguments> hugeText() {
        String big = "x".repeat(100_000);
        String spaces = " ".repeat(100_000);
        return Stream.of(
                Arguments.of("huge-description", contractWith("<description>" + big + "</description>", "")),
                Arguments.of("huge-cdata", contractWith("<description><![CDATA[" + big + "]]></description>", "")),
                Arguments.of("huge-split-text",
                        contractWith("<description>" + big + "<![CDATA[" + big + "]]>" + big + "</description>", "")),
                Arguments.of("huge-whitespace", contractWith(spaces, "")),
                Arguments.of("huge-property-text", contractWith("",
                        "<properties><property name=\"gain\" type=\"double\" default=\"1\">" + big
                                + "</property></properties>")));
    }

    private static String contractWith(String head, String tail) {
        return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
                + "<component xmlns=\"urn:arflex:contract:1\" name=\"huge\" version=\"1.0.0\">\n  " + head + "\n"
                + "  <implementation executable=\"huge\" task=\"periodic\"/>\n"
                + "  <ports/>\n  " + tail + "\n"
                + "  <timing period=\"1ms\" deadline=\"1ms\" wcet=\"50us\" priority=\"80\"/>\n"
                + "  <resources memory=\"8MiB\"/>\n"
                + "  <criticality>5</criticality>\n"
                + "  <fault restart=\"permanent\" intensity=\"3\" window=\"10s\" backoff=\"100ms\" safe=\"hold\""
                + " heartbeatTimeout=\"100ms\"/>\n"
                + "</component>\n";
    }

    /** Parses {@code xml} as a file and checks the corpus rules; returns the problems. */
    private static List<Problem> assertRefusedWith(Path xml, List<String> expected) {
        String file = xml.getFileName().toString();
        List<ContractParser.Result> r = PARSER.parseFiles(List.of(xml));
        assertFalse(r.get(0).ok(), file + " was accepted");
        List<Problem> problems = r.get(0).problems();
        assertFalse(problems.isEmpty());
        List<String> missing = new ArrayList<>();
        for (String line : expected) {
            if (line.isBlank()) {
                continue;
            }
            String[] parts = line.split("\\|", 3);
            boolean found = problems.stream().anyMatch(p -> p.section().equals(parts[0]) && p.field().equals(parts[1])
                    && p.message().contains(parts[2]));
            if (!found) {
                missing.add(line);
            }
        }
        if (!missing.isEmpty()) {
            fail(file + ": expected problems not reported: " + missing + "\nreported:\n  "
                    + String.join("\n  ", problems.stream().map(Problem::toString).toList()));
        }
        for (Problem p : problems) {
            assertEquals(xml.toString(), p.source(), "every problem names the file");
            assertFalse(p.section().isBlank());
            assertFalse(p.field().isBlank());
            assertTrue(p.toString().startsWith(xml + ":" + p.line() + ":" + p.column() + ": [§" + p.section() + "] "));
            if (!"(document)".equals(p.field()) || !p.message().startsWith("document is larger")) {
                assertTrue(p.line() > 0, "problem without a line: " + p);
            }
            assertFalse(p.section().equals("14"), "the Java validator, not the XSD, must catch this: " + p);
        }
        return problems;
    }

    @ParameterizedTest(name = "good/{0}")
    @MethodSource("good")
    void goodContractParsesPassesTheSchemaAndRoundTrips(String file) throws Exception {
        String xml = Files.readString(RESOURCES.resolve("good").resolve(file), StandardCharsets.UTF_8);
        Contract c = PARSER.parse(xml, file);
        assertEquals(List.of(), PARSER.validate(xml, file));
        String written = ContractWriter.create().write(c);
        Contract back = PARSER.parse(written, file);
        assertEquals(c, back, "round trip changed the contract; written:\n" + written);
        assertEquals(written, ContractWriter.create().write(back), "writer is not deterministic");
    }

    @Test
    void oneBadContractAmongGoodOnesFailsAlone() throws IOException {
        List<Path> files = new ArrayList<>();
        try (Stream<Path> s = Files.list(RESOURCES.resolve("good"))) {
            s.filter(p -> p.toString().endsWith(".xml")).sorted().forEach(files::add);
        }
        int goods = files.size();
        files.add(goods / 2, RESOURCES.resolve("bad/billion-laughs.xml"));
        List<ContractParser.Result> results = PARSER.parseFiles(files);
        assertEquals(goods + 1, results.size());
        for (int i = 0; i < results.size(); i++) {
            ContractParser.Result r = results.get(i);
            assertEquals(files.get(i).toString(), r.source());
            assertEquals(i != goods / 2, r.ok(), r.source() + ": " + r.problems());
        }
    }

    @Test
    void missingFileIsReportedNotThrown() {
        List<ContractParser.Result> r = PARSER.parseFiles(List.of(RESOURCES.resolve("good/does-not-exist.xml")));
        assertFalse(r.get(0).ok());
        assertEquals("2.1", r.get(0).problems().get(0).section());
    }
}
