package org.arflex.drcr.impl.services;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertNotEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.ByteArrayOutputStream;
import java.io.IOException;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.zip.ZipEntry;
import java.util.zip.ZipOutputStream;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;

/**
 * Issue 16 finding 3: {@code install http://...}, {@code update <id> <url>}, an update from
 * {@code Bundle-UpdateLocation} and {@code jar:file:...!/x.jar} installed code that then ran.
 * The gate admits only verified content or the very file of a trusted folder.
 */
class CodeGateTest {

    private final List<String> log = new ArrayList<>();

    static byte[] jar(String exe, boolean dirs) throws IOException {
        ByteArrayOutputStream b = new ByteArrayOutputStream();
        try (ZipOutputStream z = new ZipOutputStream(b)) {
            if (dirs) {
                z.putNextEntry(new ZipEntry("META-INF/"));
            }
            z.putNextEntry(new ZipEntry("META-INF/MANIFEST.MF"));
            z.write("Manifest-Version: 1.0\r\nBundle-SymbolicName: x\r\n\r\n".getBytes(StandardCharsets.UTF_8));
            if (dirs) {
                z.putNextEntry(new ZipEntry("native/"));
            }
            z.putNextEntry(new ZipEntry("native/linux-x86_64/rt"));
            z.write(exe.getBytes(StandardCharsets.UTF_8));
        }
        return b.toByteArray();
    }

    @Test
    void theDigestIsThatOfTheContentNotOfTheJarsLayout() throws IOException {
        assertEquals(ContentDigest.ofJar(jar("a", false)), ContentDigest.ofJar(jar("a", true)));
        assertNotEquals(ContentDigest.ofJar(jar("a", false)), ContentDigest.ofJar(jar("b", false)));
    }

    @Test
    void aVerifiedJarIsAdmittedFromWhereverItWasInstalled(@TempDir Path dir) throws IOException {
        CodeGate gate = new CodeGate(List.of(dir), log::add);
        byte[] j = jar("good", false);
        gate.verified(j, "arflex:deploy https://h/x.jar, sha256 ab");
        CodeGate.Decision d = gate.decide("https://h/x.jar", ContentDigest.ofJar(j));
        assertTrue(d.admitted(), d.reason());
        assertTrue(d.reason().contains("arflex:deploy https://h/x.jar"), d.reason());
    }

    @Test
    void codeInstalledFromAUrlOutsideTheVerifiedPathIsRefusedWithTheWay(@TempDir Path dir) throws IOException {
        CodeGate gate = new CodeGate(List.of(dir), log::add);
        String digest = ContentDigest.ofJar(jar("evil", false));
        for (String location : List.of("http://127.0.0.1:8000/x.jar", "https://h/x.jar", "jar:file:" + dir + "/a.jar!/x.jar",
                "ftp://127.0.0.1:2121/x.jar")) {
            CodeGate.Decision d = gate.decide(location, digest);
            assertFalse(d.admitted(), location);
            assertTrue(d.reason().startsWith("not verified: installed from '" + location + "'"), d.reason());
            assertTrue(d.reason().contains("arflex:deploy <https-url> <sha256>"), d.reason());
        }
    }

    @Test
    void theFileOfATrustedFolderIsAdmittedAsItIs(@TempDir Path dir) throws IOException {
        Path cell = Files.createDirectories(dir.resolve("cell"));
        Path f = cell.resolve("x.jar");
        Files.write(f, jar("good", false));
        CodeGate gate = new CodeGate(List.of(cell), log::add);
        CodeGate.Decision d = gate.decide(f.toUri().toString(), ContentDigest.ofJar(f));
        assertTrue(d.admitted(), d.reason());
        assertTrue(d.reason().contains(cell.toRealPath().toString()), d.reason());
    }

    /** {@code update <id> http://...} or Bundle-UpdateLocation: the location stays, the content changes. */
    @Test
    void aTrustedLocationWhoseContentCameFromElsewhereIsRefused(@TempDir Path dir) throws IOException {
        Path cell = Files.createDirectories(dir.resolve("cell"));
        Path f = cell.resolve("x.jar");
        Files.write(f, jar("good", false));
        CodeGate gate = new CodeGate(List.of(cell), log::add);
        CodeGate.Decision d = gate.decide(f.toUri().toString(), ContentDigest.ofJar(jar("evil", false)));
        assertFalse(d.admitted());
        assertTrue(d.reason().contains("updated from elsewhere"), d.reason());
        assertTrue(d.reason().contains(f.toRealPath().toString()), d.reason());
    }

    @Test
    void aFileOutsideTheTrustedFoldersOrLinkedFromThemIsRefused(@TempDir Path dir) throws IOException {
        Path cell = Files.createDirectories(dir.resolve("cell"));
        Path outside = dir.resolve("x.jar");
        Files.write(outside, jar("evil", false));
        Path link = Files.createSymbolicLink(cell.resolve("x.jar"), outside);
        CodeGate gate = new CodeGate(List.of(cell), log::add);
        String digest = ContentDigest.ofJar(outside);
        for (Path p : List.of(outside, link)) {
            CodeGate.Decision d = gate.decide(p.toUri().toString(), digest);
            assertFalse(d.admitted(), p.toString());
            assertTrue(d.reason().contains("outside the trusted folders"), d.reason());
        }
        CodeGate.Decision d = gate.decide(cell.resolve("../x.jar").toUri().toString(), digest);
        assertFalse(d.admitted(), "a path that climbs out of the folder");
    }
}
