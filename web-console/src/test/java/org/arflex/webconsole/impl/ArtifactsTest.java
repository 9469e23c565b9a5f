package org.arflex.webconsole.impl;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.ByteArrayInputStream;
import java.io.IOException;
import java.io.OutputStream;
import java.nio.file.Files;
import java.nio.file.Path;
import java.security.MessageDigest;
import java.util.HexFormat;
import java.util.jar.Attributes;
import java.util.jar.JarOutputStream;
import java.util.jar.Manifest;
import java.util.stream.Stream;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;

/** The install-from-URL rules: https or file only, SHA-256 pinned and checked, bundles only. */
class ArtifactsTest {
    @TempDir
    Path dir;

    private Path bundle(String bsn) throws IOException {
        Manifest m = new Manifest();
        m.getMainAttributes().put(Attributes.Name.MANIFEST_VERSION, "1.0");
        m.getMainAttributes().putValue("Bundle-SymbolicName", bsn + ";singleton:=true");
        m.getMainAttributes().putValue("Bundle-Version", "1.2.3");
        Path p = dir.resolve(bsn + ".jar");
        try (OutputStream out = new JarOutputStream(Files.newOutputStream(p), m)) {
            out.flush();
        }
        return p;
    }

    private static String sha(Path p) throws Exception {
        return HexFormat.of().formatHex(MessageDigest.getInstance("SHA-256").digest(Files.readAllBytes(p)));
    }

    private long staged() throws IOException {
        return stagedFiles(dir);
    }

    /** Files in {@code dataDir}'s staging folder (0 when there is none). */
    static long stagedFiles(Path dataDir) throws IOException {
        Path s = dataDir.resolve("staging");
        if (!Files.isDirectory(s)) {
            return 0;
        }
        try (Stream<Path> l = Files.list(s)) {
            return l.count();
        }
    }

    @Test
    void httpAndOtherSchemesAreRefused() {
        String pin = "a".repeat(64);
        for (String url : new String[] {"http://example.org/x.jar", "ftp://h/x.jar", "jar:file:/x.jar!/", "x.jar"}) {
            HttpError e = assertThrows(HttpError.class, () -> Artifacts.checkUrl(url, pin), url);
            assertEquals(400, e.status);
            assertTrue(e.getMessage().startsWith("url:"), e.getMessage());
        }
    }

    @Test
    void aPinIsRequiredAndMustBeSha256() {
        assertTrue(assertThrows(HttpError.class, () -> Artifacts.checkUrl("https://h/x.jar", null))
                .getMessage().contains("missing"));
        assertTrue(assertThrows(HttpError.class, () -> Artifacts.checkUrl("https://h/x.jar", "abc"))
                .getMessage().contains("64 hexadecimal"));
        assertTrue(assertThrows(HttpError.class, () -> Artifacts.checkUrl("https://user:pw@h/x.jar", "a".repeat(64)))
                .getMessage().contains("user info"));
    }

    @Test
    void aFileUrlWithTheRightPinIsStaged() throws Exception {
        Path jar = bundle("org.example.good");
        Artifacts.Staged s = Artifacts.fetch(Artifacts.checkUrl(jar.toUri().toString(), sha(jar)), sha(jar),
                dir.resolve("staging"), StagingSources.parse(dir.toString()));
        assertEquals("org.example.good", s.symbolicName());
        assertEquals("1.2.3", s.version());
        assertEquals(sha(jar), s.sha256());
        assertTrue(Files.isRegularFile(s.file()));
    }

    @Test
    void aWrongPinIsRefusedAndLeavesNothingBehind() throws Exception {
        Path jar = bundle("org.example.pinned");
        String wrong = "0".repeat(64);
        HttpError e = assertThrows(HttpError.class, () -> Artifacts.fetch(
                Artifacts.checkUrl(jar.toUri().toString(), wrong), wrong, dir.resolve("staging"),
                StagingSources.parse(dir.toString())));
        assertTrue(e.getMessage().contains(sha(jar)) && e.getMessage().contains(wrong), e.getMessage());
        assertEquals(0, staged());
    }

    @Test
    void anUploadThatIsNotABundleIsRefused() throws IOException {
        HttpError notJar = assertThrows(HttpError.class, () -> Artifacts.upload(
                new ByteArrayInputStream("hello".getBytes()), "x.jar", dir.resolve("staging")));
        assertTrue(notJar.getMessage().contains("not a jar"), notJar.getMessage());
        HttpError empty = assertThrows(HttpError.class, () -> Artifacts.upload(
                new ByteArrayInputStream(new byte[0]), "x.jar", dir.resolve("staging")));
        assertTrue(empty.getMessage().contains("empty"));
        assertEquals(0, staged());
        assertFalse(Files.exists(dir.resolve("staging/x.jar")));
    }

    @Test
    void anUploadWhoseManifestInflatesPastItsLimitIsRefused() throws IOException {
        // issue 30, finding 1: the manifest is read within a limit, whatever the jar declares
        java.io.ByteArrayOutputStream b = new java.io.ByteArrayOutputStream();
        try (java.util.zip.ZipOutputStream z = new java.util.zip.ZipOutputStream(b)) {
            z.putNextEntry(new java.util.zip.ZipEntry("META-INF/MANIFEST.MF"));
            z.write("Manifest-Version: 1.0\r\nBundle-SymbolicName: bomb\r\n".getBytes());
            byte[] pad = "X-Pad: 0\r\n".repeat(1 << 16).getBytes();
            for (int i = 0; i < 8; i++) {
                z.write(pad); // 5 MiB of headers in all
            }
        }
        HttpError e = assertThrows(HttpError.class, () -> Artifacts.upload(new ByteArrayInputStream(b.toByteArray()),
                "bomb.jar", dir.resolve("staging")));
        assertTrue(e.getMessage().contains("upload bomb.jar: entry META-INF/MANIFEST.MF inflates past the limit of "
                + Artifacts.MAX_MANIFEST + " bytes"), e.getMessage());
        assertEquals(0, staged());
    }
}
