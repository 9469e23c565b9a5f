package org.arflex.apicheck;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.Map;
import java.util.SortedMap;
import java.util.SortedSet;
import java.util.TreeMap;
import java.util.TreeSet;
import org.arflex.apicheck.ApiBaseline.Api;
import org.arflex.apicheck.fixture.Gauge;
import org.arflex.apicheck.fixture.Probe;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;

/** The API baseline check fails on changes without the version bump they need. */
class ApiBaselineCheckTest {

    private static final String PKG = "org.arflex.apicheck.fixture";
    private static final String GAUGE = "org.arflex.apicheck.fixture.Gauge";
    private static final String PROBE = "org.arflex.apicheck.fixture.Probe";

    private static SortedSet<String> fixture() throws Exception {
        return ApiSignatures.of(Path.of("target/test-classes"), PKG, ApiBaselineCheckTest.class.getClassLoader());
    }

    private static SortedMap<String, Api> one(String version, SortedSet<String> sigs) {
        return new TreeMap<>(Map.of(PKG, new Api(version, sigs)));
    }

    private static SortedSet<String> plus(SortedSet<String> s, String line) {
        SortedSet<String> out = new TreeSet<>(s);
        out.add(line);
        return out;
    }

    @Test
    void signaturesArePublicMembersWithGenericsAndKinds() throws Exception {
        assertEquals(List.of(
                "M " + GAUGE + " public double " + GAUGE + ".read()",
                "M " + GAUGE + " public " + GAUGE + "()",
                "M " + PROBE + " public abstract double " + PROBE + ".sample(" + GAUGE + ")",
                "M " + PROBE + " public default java.lang.String " + PROBE + ".name()",
                "T " + GAUGE + " class public final provider",
                "T " + PROBE + " interface public abstract consumer"), new ArrayList<>(fixture()));
        assertEquals(fixture().size(), ApiSignatures.of(Gauge.class, false).size() + ApiSignatures.of(Probe.class, false).size());
    }

    @Test
    void unchangedPasses() throws Exception {
        assertEquals(List.of(), ApiBaseline.problems(one("1.0.0", fixture()), one("1.0.0", fixture())));
    }

    @Test
    void removalNeedsTheNextMajor() throws Exception {
        SortedMap<String, Api> was = one("1.2.0", plus(fixture(), "M " + GAUGE + " public void " + GAUGE + ".reset()"));
        List<String> p = ApiBaseline.problems(was, one("1.3.0", fixture()));
        assertEquals(1, p.size());
        assertTrue(p.get(0).startsWith(PKG + ": a major change needs version 2.0.0 or above (recorded 1.2.0, now 1.3.0)"),
                p.get(0));
        assertTrue(p.get(0).contains("removed or changed: M " + GAUGE + " public void " + GAUGE + ".reset()"), p.get(0));
        assertEquals(List.of(), ApiBaseline.problems(was, one("2.0.0", fixture())));
    }

    @Test
    void additionNeedsTheNextMinor() throws Exception {
        SortedMap<String, Api> was = one("0.4.0", fixture());
        SortedMap<String, Api> grown = one("0.4.1", plus(fixture(), "M " + GAUGE + " public long " + GAUGE + ".count()"));
        List<String> p = ApiBaseline.problems(was, grown);
        assertEquals(1, p.size());
        assertTrue(p.get(0).startsWith(PKG + ": a minor change needs version 0.5.0 or above"), p.get(0));
        assertEquals(List.of(), ApiBaseline.problems(was, one("0.5.0", grown.get(PKG).signatures())));
    }

    @Test
    void anAbstractMethodAddedToAConsumerTypeIsMajorButNotToAProviderType() throws Exception {
        String added = "M " + PROBE + " public abstract int " + PROBE + ".rate()";
        List<String> p = ApiBaseline.problems(one("1.0.0", fixture()), one("1.1.0", plus(fixture(), added)));
        assertEquals(1, p.size());
        assertTrue(p.get(0).contains("needs version 2.0.0") && p.get(0).contains("clients may implement"), p.get(0));
        SortedSet<String> provider = new TreeSet<>(fixture());
        provider.remove("T " + PROBE + " interface public abstract consumer");
        provider.add("T " + PROBE + " interface public abstract provider");
        assertEquals(List.of(), ApiBaseline.problems(one("1.0.0", provider), one("1.1.0", plus(provider, added))));
    }

    @Test
    void lowerVersionsAndLostOrUnrecordedPackagesFail() throws Exception {
        assertEquals(List.of(PKG + ": version 0.9.0 is below the recorded 1.0.0"),
                ApiBaseline.problems(one("1.0.0", fixture()), one("0.9.0", fixture())));
        assertEquals(List.of(PKG + " 1.0.0 is no longer exported (a break for every importer)"),
                ApiBaseline.problems(one("1.0.0", fixture()), new TreeMap<>()));
        assertTrue(ApiBaseline.problems(new TreeMap<>(), one("1.0.0", fixture())).get(0).contains("is not recorded"));
    }

    @Test
    void exportHeadersWithUsesAreSplitOutsideQuotes() {
        assertEquals(Map.of("a.b", "1.0.0", "c", "0.7.0", "d", "0.0.0"),
                Exports.parse("a.b;version=\"1.0.0\";uses:=\"x,y\",c;version=\"0.7.0\",d"));
    }

    @Test
    void verifyRecordsOnlyWhatPassesAndThenFailsOnABreak(@TempDir Path dir) throws Exception {
        Path file = dir.resolve("api-baseline.txt");
        Path manifest = manifest(dir, "1.0.0");
        Path classes = Path.of("target/test-classes");
        // A first baseline: nothing recorded, so the check asks for the record.
        AssertionError none = assertThrows(AssertionError.class, () -> ApiBaseline.verify(classes, manifest, file));
        assertTrue(none.getMessage().contains("is not recorded"), none.getMessage());
        record(classes, manifest, file);
        ApiBaseline.verify(classes, manifest, file);
        assertEquals(ApiBaseline.format(one("1.0.0", fixture())), Files.readAllLines(file, StandardCharsets.UTF_8));
        // A later break: the record had a method the classes no longer have.
        List<String> lines = new ArrayList<>(Files.readAllLines(file, StandardCharsets.UTF_8));
        lines.add("  M " + GAUGE + " public void " + GAUGE + ".reset()");
        Files.write(file, lines, StandardCharsets.UTF_8);
        AssertionError broke = assertThrows(AssertionError.class, () -> ApiBaseline.verify(classes, manifest, file));
        assertTrue(broke.getMessage().contains("a major change needs version 2.0.0"), broke.getMessage());
        // Recording does not accept it either; the version bump does.
        assertThrows(AssertionError.class, () -> record(classes, manifest, file));
        ApiBaseline.verify(classes, manifest(dir, "2.0.0"), file);
    }

    private static Path manifest(Path dir, String version) throws IOException {
        Path m = dir.resolve("MANIFEST-" + version + ".MF");
        Files.writeString(m, "Manifest-Version: 1.0\nExport-Package: " + PKG + ";version=\"" + version + "\"\n");
        return m;
    }

    private static void record(Path classes, Path manifest, Path file) throws Exception {
        System.setProperty(ApiBaseline.WRITE, "true");
        try {
            ApiBaseline.verify(classes, manifest, file);
        } finally {
            System.clearProperty(ApiBaseline.WRITE);
        }
    }
}
