package org.arflex.contract;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertTrue;
import static org.junit.jupiter.api.Assertions.fail;

import java.io.IOException;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.stream.Stream;
import org.junit.jupiter.params.ParameterizedTest;
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
        List<ContractParser.Result> r = PARSER.parseFiles(List.of(xml));
        assertFalse(r.get(0).ok(), file + " was accepted");
        List<Problem> problems = r.get(0).problems();
        assertFalse(problems.isEmpty());
        List<String> missing = new ArrayList<>();
        for (String line : Files.readAllLines(exp, StandardCharsets.UTF_8)) {
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
