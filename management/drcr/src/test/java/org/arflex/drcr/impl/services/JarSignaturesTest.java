package org.arflex.drcr.impl.services;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.ByteArrayOutputStream;
import java.io.IOException;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.security.KeyStore;
import java.util.ArrayList;
import java.util.List;
import java.util.Map;
import java.util.zip.ZipEntry;
import java.util.zip.ZipOutputStream;
import org.junit.jupiter.api.BeforeAll;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;

/**
 * Issue 16, "one gate for code": a jar signature by a key of the runtime's trust store is the
 * second accepted form. Standard signatures (made here as jarsigner makes them), every entry
 * covered, every way of changing a signed jar refused by name (docs/DECISIONS.md D14).
 */
class JarSignaturesTest {

    @TempDir
    static Path keys;

    static Signing.Key one;
    static Signing.Key stranger;
    static Signing.Key expired;
    static KeyStore trusted;

    @BeforeAll
    static void makeKeys() throws Exception {
        one = Signing.key(keys, "one", "CN=Integrator One, O=Cell Maker");
        stranger = Signing.key(keys, "stranger", "CN=Stranger");
        expired = Signing.key(keys, "old", "CN=Old Integrator", "-startdate", "-30d", "-validity", "2");
        trusted = new TrustStore(Signing.trustStore(keys, one, expired)).load();
    }

    /** A component bundle: manifest, contract, RT executable, directories as jar tools write them. */
    static byte[] bundle(String exe) throws IOException {
        ByteArrayOutputStream b = new ByteArrayOutputStream();
        try (ZipOutputStream z = new ZipOutputStream(b)) {
            z.putNextEntry(new ZipEntry("META-INF/"));
            z.putNextEntry(new ZipEntry("META-INF/MANIFEST.MF"));
            z.write(("Manifest-Version: 1.0\r\nBundle-SymbolicName: x\r\n"
                    + "ARFLEX-Contract: OSGI-INF/arflex/x.xml\r\n\r\n").getBytes(StandardCharsets.UTF_8));
            z.putNextEntry(new ZipEntry("OSGI-INF/arflex/x.xml"));
            z.write("<component name=\"x\"/>".getBytes(StandardCharsets.UTF_8));
            z.putNextEntry(new ZipEntry("native/"));
            z.putNextEntry(new ZipEntry("native/linux-x86_64/rt"));
            z.write(exe.getBytes(StandardCharsets.UTF_8));
        }
        return b.toByteArray();
    }

    @Test
    void aJarSignedByATrustedKeyIsAcceptedWithItsSigner(@TempDir Path dir) throws Exception {
        byte[] jar = Signing.sign(dir, bundle("good"), one);
        JarSignatures.Verdict v = JarSignatures.check(jar, trusted);
        assertTrue(v.accepted(), v.reason());
        assertEquals("CN=Integrator One,O=Cell Maker", v.signer());
        assertEquals(JarSignatures.fingerprint(one.cert()), v.fingerprint());
        assertTrue(v.fingerprint().matches("([0-9A-F]{2}:){31}[0-9A-F]{2}"), v.fingerprint());
        assertEquals("signed by CN=Integrator One,O=Cell Maker, sha256 " + v.fingerprint(), v.describe());
        assertTrue(JarSignatures.check(Signing.write(dir.resolve("x.jar"), jar), trusted).accepted());
    }

    @Test
    void anUnsignedJarIsRefused() throws Exception {
        JarSignatures.Verdict v = JarSignatures.check(bundle("good"), trusted);
        assertFalse(v.accepted());
        assertEquals("unsigned: no signature file in META-INF", v.reason());
    }

    @Test
    void aJarSignedByAnUnknownKeyIsRefusedNamingTheKey(@TempDir Path dir) throws Exception {
        JarSignatures.Verdict v = JarSignatures.check(Signing.sign(dir, bundle("good"), stranger), trusted);
        assertFalse(v.accepted());
        assertEquals("signed by an unknown key: CN=Stranger, sha256 " + JarSignatures.fingerprint(stranger.cert())
                + " is not in the trust store", v.reason());
    }

    @Test
    void anEntryAddedAfterSigningIsRefusedByName(@TempDir Path dir) throws Exception {
        byte[] signed = Signing.sign(dir, bundle("good"), one);
        byte[] appended = Signing.rewrite(signed, l -> {
            l.add(Map.entry("native/linux-x86_64/evil", "evil".getBytes(StandardCharsets.UTF_8)));
            return l;
        });
        byte[] inserted = Signing.rewrite(signed, l -> {
            l.add(1, Map.entry("aaa/evil.so", "evil".getBytes(StandardCharsets.UTF_8)));
            return l;
        });
        JarSignatures.Verdict v = JarSignatures.check(appended, trusted);
        assertFalse(v.accepted());
        assertEquals("refused: entry native/linux-x86_64/evil is not covered by the signature (added after signing?)",
                v.reason());
        v = JarSignatures.check(inserted, trusted);
        assertFalse(v.accepted());
        assertTrue(v.reason().contains("entry aaa/evil.so is not covered by the signature"), v.reason());
    }

    @Test
    void anUnsignedSignatureLikeFileAddedAfterSigningIsRefusedByName(@TempDir Path dir) throws Exception {
        // issue 30, finding 10: the JDK skips these names when it checks coverage, the gate must not
        byte[] signed = Signing.sign(dir, bundle("good"), one);
        for (String added : List.of("META-INF/EVIL.EC", "META-INF/SIG-EVIL", "META-INF/EVIL.RSA", "META-INF/EVIL.DSA",
                "META-INF/EVIL.SF")) {
            byte[] jar = Signing.rewrite(signed, l -> {
                l.add(Map.entry(added, "evil".getBytes(StandardCharsets.UTF_8)));
                return l;
            });
            JarSignatures.Verdict v = JarSignatures.check(jar, trusted);
            assertFalse(v.accepted(), added + " was admitted: " + v.describe());
            assertTrue(v.reason().contains(added), added + ": " + v.reason());
        }
    }

    @Test
    void aModifiedEntryIsRefusedByName(@TempDir Path dir) throws Exception {
        byte[] signed = Signing.sign(dir, bundle("good"), one);
        byte[] modified = Signing.rewrite(signed, l -> l.stream()
                .map(e -> e.getKey().equals("native/linux-x86_64/rt")
                        ? Map.entry(e.getKey(), "evil".getBytes(StandardCharsets.UTF_8)) : e)
                .collect(java.util.stream.Collectors.toCollection(ArrayList::new)));
        JarSignatures.Verdict v = JarSignatures.check(modified, trusted);
        assertFalse(v.accepted());
        assertTrue(v.reason().startsWith("tampered: entry native/linux-x86_64/rt does not match its signature"),
                v.reason());
    }

    /** The bundle's headers (ARFLEX-Contract, Bundle-NativeCode, ...) are signed too. */
    @Test
    void aChangedBundleHeaderIsRefused(@TempDir Path dir) throws Exception {
        byte[] signed = Signing.sign(dir, bundle("good"), one);
        byte[] changed = Signing.rewrite(signed, l -> l.stream()
                .map(e -> e.getKey().equals("META-INF/MANIFEST.MF") ? Map.entry(e.getKey(), new String(e.getValue(),
                        StandardCharsets.UTF_8).replace("Bundle-SymbolicName: x", "Bundle-SymbolicName: y")
                        .getBytes(StandardCharsets.UTF_8)) : e)
                .collect(java.util.stream.Collectors.toCollection(ArrayList::new)));
        JarSignatures.Verdict v = JarSignatures.check(changed, trusted);
        assertFalse(v.accepted());
        assertTrue(v.reason().startsWith("tampered: "), v.reason());
        assertTrue(v.reason().contains("Manifest main attributes"), v.reason());
    }

    @Test
    void anEntryRemovedAfterSigningIsRefusedByName(@TempDir Path dir) throws Exception {
        byte[] signed = Signing.sign(dir, bundle("good"), one);
        byte[] removed = Signing.rewrite(signed, l -> {
            l.removeIf(e -> e.getKey().equals("OSGI-INF/arflex/x.xml"));
            return l;
        });
        JarSignatures.Verdict v = JarSignatures.check(removed, trusted);
        assertFalse(v.accepted());
        assertEquals("refused: entry OSGI-INF/arflex/x.xml is in the signed manifest but missing from the jar "
                + "(removed after signing?)", v.reason());
    }

    /** Signed by the trusted key, then an entry added and the whole signed again by another key. */
    @Test
    void entriesSignedByDifferentSignersAreRefused(@TempDir Path dir) throws Exception {
        byte[] signed = Signing.sign(dir, bundle("good"), one);
        byte[] added = Signing.rewrite(signed, l -> {
            l.add(Map.entry("native/linux-x86_64/evil", "evil".getBytes(StandardCharsets.UTF_8)));
            return l;
        });
        JarSignatures.Verdict v = JarSignatures.check(Signing.sign(dir, added, stranger), trusted);
        assertFalse(v.accepted());
        assertTrue(v.reason().startsWith("refused: signers differ between entries: "), v.reason());
        assertTrue(v.reason().contains("native/linux-x86_64/evil by CN=Stranger"), v.reason());
    }

    /** A signature file changed after signing: its block no longer verifies. */
    @Test
    void aForgedSignatureFileIsRefused(@TempDir Path dir) throws Exception {
        byte[] signed = Signing.sign(dir, bundle("good"), one);
        byte[] forged = Signing.rewrite(signed, l -> l.stream()
                .map(e -> e.getKey().equals("META-INF/ONE.SF") ? Map.entry(e.getKey(), new String(e.getValue(),
                        StandardCharsets.UTF_8).replace("Created-By", "Created-by").getBytes(StandardCharsets.UTF_8)) : e)
                .collect(java.util.stream.Collectors.toCollection(ArrayList::new)));
        JarSignatures.Verdict v = JarSignatures.check(forged, trusted);
        assertFalse(v.accepted());
        assertTrue(v.reason().startsWith("tampered: the signature file META-INF/ONE.EC does not verify ("),
                v.reason());
    }

    @Test
    void aJarSignedEntirelyByATrustedAndAnUnknownKeyIsAccepted(@TempDir Path dir) throws Exception {
        byte[] both = Signing.sign(dir, Signing.sign(dir, bundle("good"), stranger), one);
        JarSignatures.Verdict v = JarSignatures.check(both, trusted);
        assertTrue(v.accepted(), v.reason());
        assertTrue(v.signer().startsWith("CN=Integrator One"), v.signer());
    }

    /** D14: the trust store decides, not the calendar; the date is reported. */
    @Test
    void anExpiredTrustedCertificateIsAcceptedAndSaysSo(@TempDir Path dir) throws Exception {
        JarSignatures.Verdict v = JarSignatures.check(Signing.sign(dir, bundle("good"), expired), trusted);
        assertTrue(v.accepted(), v.reason());
        assertTrue(v.describe().startsWith("signed by CN=Old Integrator, sha256 "), v.describe());
        assertTrue(v.describe().contains("; its certificate expired on "), v.describe());
    }

    @Test
    void anEmptyTrustStoreTrustsNothing(@TempDir Path dir) throws Exception {
        JarSignatures.Verdict v = JarSignatures.check(Signing.sign(dir, bundle("good"), one),
                new TrustStore(Files.createDirectory(dir.resolve("empty"))).load());
        assertFalse(v.accepted());
        assertTrue(v.reason().startsWith("signed by an unknown key: CN=Integrator One"), v.reason());
    }

    @Test
    void signatureFilesAreTheOnlyEntriesASignatureDoesNotCover() {
        for (String n : List.of("META-INF/MANIFEST.MF", "META-INF/ONE.SF", "META-INF/one.ec", "META-INF/X.RSA",
                "META-INF/X.DSA", "META-INF/SIG-A.B")) {
            assertTrue(JarSignatures.signingFile(n), n);
        }
        for (String n : List.of("META-INF/maven/x/pom.xml", "META-INF/x/ONE.SF", "native/ONE.SF", "META-INF/rt",
                "OSGI-INF/arflex/x.xml")) {
            assertFalse(JarSignatures.signingFile(n), n);
        }
    }
}
