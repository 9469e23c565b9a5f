package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.List;
import java.util.concurrent.TimeUnit;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;

/**
 * {@code scripts/test-summary.sh} (D82) on report trees written here: the suites it expects are
 * derived from the tree's test sources and {@code tests/suite/ctest.expected}; a missing or empty
 * suite, a CTest family or test missing from its report and a skip not on
 * {@code tests/suite/skips.allowed} each fail the run, named, and count in the closing line.
 */
class SuiteSummaryTest {

    static final Path SCRIPT = Components.root().resolve("scripts/test-summary.sh");

    record Run(int status, String out) {
        String last() {
            List<String> l = out.lines().toList();
            return l.isEmpty() ? "" : l.get(l.size() - 1);
        }
    }

    static void source(Path root, String module, String cls, String body) throws IOException {
        Path f = root.resolve(module + "/src/test/java/p/" + cls + ".java");
        Files.createDirectories(f.getParent());
        Files.writeString(f, "package p;\nimport org.junit.jupiter.api.Test;\n" + body + "\n");
    }

    static void testClass(Path root, String module, String cls) throws IOException {
        source(root, module, cls, "class " + cls + " { @Test void a() {} }");
    }

    /** A Surefire report of p.cls: {@code cases} passed test cases, then {@code skippedCases} skipped ones. */
    static void report(Path root, String module, String cls, int cases, int skippedCases) throws IOException {
        StringBuilder x = new StringBuilder("<?xml version=\"1.0\"?>\n<testsuite name=\"p." + cls + "\" tests=\""
                + (cases + skippedCases) + "\" failures=\"0\" errors=\"0\" skipped=\"" + skippedCases + "\">\n");
        for (int i = 0; i < cases; i++) {
            x.append(" <testcase name=\"ok").append(i).append("()\" classname=\"p.").append(cls).append("\"/>\n");
        }
        for (int i = 0; i < skippedCases; i++) {
            x.append(" <testcase name=\"sk").append(i).append("()\" classname=\"p.").append(cls)
                    .append("\"><skipped message=\"no widget here\"/></testcase>\n");
        }
        x.append("</testsuite>\n");
        Path f = root.resolve(module + "/target/surefire-reports/TEST-p." + cls + ".xml");
        Files.createDirectories(f.getParent());
        Files.writeString(f, x);
    }

    static void ctestReport(Path root, String dir, String... names) throws IOException {
        StringBuilder x = new StringBuilder("<?xml version=\"1.0\"?>\n<testsuite name=\"Linux\" tests=\"" + names.length
                + "\" failures=\"0\" disabled=\"0\" skipped=\"0\">\n");
        for (String n : names) {
            x.append(" <testcase name=\"").append(n).append("\" classname=\"").append(n).append("\" status=\"run\"/>\n");
        }
        Path f = root.resolve(dir + "/ctest-junit.xml");
        Files.createDirectories(f.getParent());
        Files.writeString(f, x.append("</testsuite>\n"));
    }

    static void list(Path root, String file, String... lines) throws IOException {
        Path f = root.resolve("tests/suite/" + file);
        Files.createDirectories(f.getParent());
        Files.write(f, List.of(lines));
    }

    static Run run(Path root, String... extra) throws IOException, InterruptedException {
        List<String> cmd = new java.util.ArrayList<>(List.of("bash", SCRIPT.toString()));
        cmd.addAll(List.of(extra));
        cmd.add(root.toString());
        Process p = new ProcessBuilder(cmd).redirectErrorStream(true).start();
        String out = new String(p.getInputStream().readAllBytes(), StandardCharsets.UTF_8);
        assertTrue(p.waitFor(60, TimeUnit.SECONDS), "test-summary.sh did not end");
        return new Run(p.exitValue(), out);
    }

    @Test
    void everyExpectedSuiteWithTestsPasses(@TempDir Path root) throws Exception {
        testClass(root, "m", "ATest");
        testClass(root, "it", "BIT");
        report(root, "m", "ATest", 2, 0);
        report(root, "it", "BIT", 3, 0);
        Run r = run(root);
        assertEquals(0, r.status(), r.out());
        assertEquals("5 passed, 0 failed", r.last(), r.out());
    }

    @Test
    void aSuiteWithoutItsReportFailsByName(@TempDir Path root) throws Exception {
        testClass(root, "m", "ATest");
        testClass(root, "it", "BIT");
        report(root, "m", "ATest", 2, 0);
        Run r = run(root);
        assertEquals(1, r.status(), r.out());
        assertTrue(r.out().contains("MISSING p.BIT: no TEST-p.BIT.xml report"), r.out());
        assertEquals("2 passed, 1 failed", r.last(), r.out());
    }

    @Test
    void anEmptySuiteFails(@TempDir Path root) throws Exception {
        testClass(root, "m", "ATest");
        testClass(root, "m", "CTest");
        report(root, "m", "ATest", 2, 0);
        report(root, "m", "CTest", 0, 0);
        Run r = run(root);
        assertEquals(1, r.status(), r.out());
        assertTrue(r.out().contains("EMPTY p.CTest: its report holds 0 tests"), r.out());
        assertEquals("2 passed, 1 failed", r.last(), r.out());
    }

    @Test
    void benchesHelpersAndAbstractClassesAreNotExpected(@TempDir Path root) throws Exception {
        testClass(root, "m", "ATest");
        report(root, "m", "ATest", 1, 0);
        testClass(root, "it", "SoakBench");                       // no Surefire/Failsafe include matches
        source(root, "it", "RuntimeUnderTest", "class RuntimeUnderTest { }"); // no test method
        source(root, "it", "BaseTest", "abstract class BaseTest { @Test void a() {} }");
        Run r = run(root, "--list-expected");
        assertEquals("java p.ATest", r.out().strip(), r.out());
        Run s = run(root);
        assertEquals(0, s.status(), s.out());
        assertEquals("1 passed, 0 failed", s.last(), s.out());
    }

    @Test
    void aSkipNotOnTheAllowListFails(@TempDir Path root) throws Exception {
        testClass(root, "m", "ATest");
        report(root, "m", "ATest", 1, 1);
        Run r = run(root);
        assertEquals(1, r.status(), r.out());
        assertTrue(r.out().contains("SKIPPED, NOT ALLOWED p.ATest.sk0(): no widget here"), r.out());
        assertEquals("1 passed, 1 failed, 1 skipped", r.last(), r.out());
    }

    @Test
    void anAllowedSkipPassesAndIsReported(@TempDir Path root) throws Exception {
        testClass(root, "m", "ATest");
        report(root, "m", "ATest", 1, 1);
        list(root, "skips.allowed", "# comment", "p.ATest.sk* the widget is absent on CI machines by design");
        Run r = run(root);
        assertEquals(0, r.status(), r.out());
        assertTrue(r.out().contains("skipped (allowed: the widget is absent on CI machines by design) p.ATest.sk0()"),
                r.out());
        assertEquals("1 passed, 0 failed, 1 skipped", r.last(), r.out());
    }

    @Test
    void anAllowListLineWithoutAReasonFails(@TempDir Path root) throws Exception {
        testClass(root, "m", "ATest");
        report(root, "m", "ATest", 1, 1);
        list(root, "skips.allowed", "p.ATest.sk*");
        Run r = run(root);
        assertEquals(1, r.status(), r.out());
        assertTrue(r.out().contains("skips.allowed:1: want '<test pattern> <reason>'"), r.out());
        assertTrue(r.out().contains("SKIPPED, NOT ALLOWED p.ATest.sk0()"), r.out());
    }

    @Test
    void aMissingCtestReportOrFamilyFails(@TempDir Path root) throws Exception {
        list(root, "ctest.expected", "target/native rt-core.", "target/native sim.comp.", "target/asan rt-core.");
        ctestReport(root, "target/native", "rt-core.ports", "rt-core.fault");
        Run r = run(root);
        assertEquals(1, r.status(), r.out());
        assertTrue(r.out().contains("MISSING ctest sim.comp.* in " + root.resolve("target/native")), r.out());
        assertTrue(r.out().contains("MISSING ctest " + root.resolve("target/asan") + ": no "), r.out());
        assertFalse(r.out().contains("MISSING ctest rt-core."), r.out());
        assertEquals("2 passed, 2 failed", r.last(), r.out());

        ctestReport(root, "target/native", "rt-core.ports", "sim.comp.cycle");
        ctestReport(root, "target/asan", "rt-core.ports");
        Run ok = run(root);
        assertEquals(0, ok.status(), ok.out());
        assertEquals("3 passed, 0 failed", ok.last(), ok.out());
    }

    @Test
    void aTreeWithNoReportFails(@TempDir Path root) throws Exception {
        Run r = run(root);
        assertEquals(1, r.status(), r.out());
        assertEquals("0 passed, 0 failed", r.last(), r.out());
    }

    /** The real tree: what the lead's full run must have, benches and helpers left out. */
    @Test
    void theRepositorysExpectedSuites() throws Exception {
        Run r = run(Components.root(), "--list-expected");
        assertEquals(0, r.status(), r.out());
        List<String> java = r.out().lines().filter(l -> l.startsWith("java ")).map(l -> l.substring(5)).toList();
        assertTrue(java.contains("org.arflex.it.SuiteSummaryTest"), r.out());
        assertTrue(java.contains("org.arflex.webconsole.WebConsoleDeployIT"), r.out());
        assertTrue(java.contains("org.arflex.contract.ContractFuzzTest"), r.out());
        assertFalse(java.contains("org.arflex.it.CellAccuracyBench"), r.out());
        assertFalse(java.contains("org.arflex.webconsole.RuntimeUnderTest"), r.out());
        assertTrue(r.out().lines().anyMatch(l -> l.startsWith("ctest ") && l.endsWith("native-asan rt-core.")), r.out());
    }
}
