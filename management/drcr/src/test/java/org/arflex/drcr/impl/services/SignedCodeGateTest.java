package org.arflex.drcr.impl.services;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertNotNull;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.ByteArrayInputStream;
import java.io.IOException;
import java.io.InputStream;
import java.lang.reflect.Proxy;
import java.net.URL;
import java.net.URLConnection;
import java.net.URLStreamHandler;
import java.nio.file.Files;
import java.nio.file.Path;
import java.nio.file.attribute.PosixFilePermissions;
import java.util.ArrayList;
import java.util.Collections;
import java.util.List;
import java.util.Map;
import java.util.TreeSet;
import org.junit.jupiter.api.BeforeAll;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;
import org.osgi.framework.Bundle;
import org.osgi.framework.BundleContext;

/**
 * The code gate's third accepted form (issue 16; docs/DECISIONS.md D14): a bundle signed
 * entirely by a key of the runtime's trust store runs its RT halves from wherever it was
 * installed; unsigned and unpinned code is refused with the reason; a trust store others can
 * write to trusts nothing.
 */
class SignedCodeGateTest {

    @TempDir
    static Path keys;

    static Signing.Key one;
    static Signing.Key stranger;

    private final List<String> log = new ArrayList<>();

    @BeforeAll
    static void makeKeys() throws Exception {
        one = Signing.key(keys, "one", "CN=Integrator One");
        stranger = Signing.key(keys, "stranger", "CN=Stranger");
    }

    /** An installed bundle as Felix shows it: location and entries (Felix keeps its own copy). */
    static Bundle installed(String location, byte[] jar) throws IOException {
        Map<String, byte[]> entries = ContentDigest.entries(jar);
        return (Bundle) Proxy.newProxyInstance(Bundle.class.getClassLoader(), new Class<?>[] {Bundle.class},
                (proxy, m, args) -> switch (m.getName()) {
                    case "getLocation" -> location;
                    case "getBundleId" -> 42L;
                    case "getSymbolicName" -> "x";
                    case "getEntryPaths" -> {
                        String dir = ((String) args[0]).replaceFirst("^/", "");
                        TreeSet<String> children = new TreeSet<>();
                        for (String n : entries.keySet()) {
                            if (n.startsWith(dir)) {
                                int slash = n.indexOf('/', dir.length());
                                children.add(slash < 0 ? n : n.substring(0, slash + 1));
                            }
                        }
                        yield children.isEmpty() ? null : Collections.enumeration(children);
                    }
                    case "getEntry" -> {
                        byte[] b = entries.get(((String) args[0]).replaceFirst("^/", ""));
                        yield b == null ? null : new URL("test", "", -1, "/" + args[0], new URLStreamHandler() {
                            @Override
                            protected URLConnection openConnection(URL u) {
                                return new URLConnection(u) {
                                    @Override
                                    public void connect() {
                                    }

                                    @Override
                                    public InputStream getInputStream() {
                                        return new ByteArrayInputStream(b);
                                    }
                                };
                            }
                        });
                    }
                    case "hashCode" -> System.identityHashCode(proxy);
                    case "equals" -> proxy == args[0];
                    default -> throw new UnsupportedOperationException(m.getName());
                });
    }

    private static Path store(Path dir, Signing.Key... trusted) throws Exception {
        return Signing.trustStore(dir, trusted);
    }

    @Test
    void aBundleSignedByATrustedKeyIsAdmittedFromWhereverItWasInstalled(@TempDir Path dir) throws Exception {
        CodeGate gate = new CodeGate(List.of(dir.resolve("cell")), store(dir, one), log::add);
        Bundle b = installed("https://h/x.jar", Signing.sign(dir, JarSignaturesTest.bundle("good"), one));
        assertNull(gate.refusal(b), String.join("\n", log));
        String fp = JarSignatures.fingerprint(one.cert());
        assertTrue(log.get(0).contains("admitted: signed by CN=Integrator One, sha256 " + fp + " (trust store "
                + dir.resolve("trust") + ")"), log.get(0));
    }

    /** "Unsigned and unpinned code is refused with the reason." */
    @Test
    void unsignedAndUnpinnedCodeIsRefusedWithTheReason(@TempDir Path dir) throws Exception {
        CodeGate gate = new CodeGate(List.of(dir.resolve("cell")), store(dir, one), log::add);
        String why = gate.refusal(installed("https://h/x.jar", JarSignaturesTest.bundle("evil")));
        assertNotNull(why);
        assertTrue(why.startsWith("bundle 42 (x, location https://h/x.jar) not verified: installed from "
                + "'https://h/x.jar', outside the verified path and the trusted folders; not signed by a trusted key: "
                + "unsigned: no signature file in META-INF; "), why);
        assertTrue(why.contains("arflex:deploy <https-url> <sha256>"), why);
        assertTrue(why.contains("sign it with a key of the trust store"), why);
    }

    @Test
    void aBundleSignedByAnUnknownKeyIsRefusedNamingTheKey(@TempDir Path dir) throws Exception {
        CodeGate gate = new CodeGate(List.of(dir.resolve("cell")), store(dir, one), log::add);
        String why = gate.refusal(installed("https://h/x.jar", Signing.sign(dir, JarSignaturesTest.bundle("x"), stranger)));
        assertNotNull(why);
        assertTrue(why.contains("not signed by a trusted key: signed by an unknown key: CN=Stranger, sha256 "
                + JarSignatures.fingerprint(stranger.cert()) + " is not in the trust store"), why);
    }

    @Test
    void aSignedBundleWithAnEntryAddedOrChangedIsRefusedByName(@TempDir Path dir) throws Exception {
        CodeGate gate = new CodeGate(List.of(dir.resolve("cell")), store(dir, one), log::add);
        byte[] signed = Signing.sign(dir, JarSignaturesTest.bundle("good"), one);
        byte[] added = Signing.rewrite(signed, l -> {
            l.add(Map.entry("native/linux-x86_64/evil", new byte[] {1}));
            return l;
        });
        byte[] changed = Signing.rewrite(signed, l -> l.stream()
                .map(e -> e.getKey().equals("native/linux-x86_64/rt") ? Map.entry(e.getKey(), new byte[] {1}) : e)
                .collect(java.util.stream.Collectors.toCollection(ArrayList::new)));
        String why = gate.refusal(installed("https://h/x.jar", added));
        assertTrue(why.contains("not signed by a trusted key: refused: entry native/linux-x86_64/evil is not covered "
                + "by the signature"), why);
        why = gate.refusal(installed("https://h/x.jar", changed));
        assertTrue(why.contains("not signed by a trusted key: tampered: entry native/linux-x86_64/rt does not match "
                + "its signature"), why);
    }

    @Test
    void aTrustStoreOthersCanWriteToTrustsNoSignature(@TempDir Path dir) throws Exception {
        Path t = store(dir, one);
        CodeGate gate = new CodeGate(List.of(dir.resolve("cell")), t, log::add);
        Bundle b = installed("https://h/x.jar", Signing.sign(dir, JarSignaturesTest.bundle("good"), one));
        assertNull(gate.refusal(b));

        Files.setPosixFilePermissions(t, PosixFilePermissions.fromString("rwxrwxrwx"));
        String why = gate.refusal(b);
        assertNotNull(why, "a world-writable trust store folder");
        assertTrue(why.contains("the trust store folder " + t.toRealPath() + " is writable by group or others "
                + "(rwxrwxrwx): the trust store is refused, no signature is trusted"), why);

        Files.setPosixFilePermissions(t, PosixFilePermissions.fromString("rwxr-xr-x"));
        Path crt;
        try (var files = Files.list(t)) {
            crt = files.findFirst().orElseThrow();
        }
        Files.setPosixFilePermissions(crt, PosixFilePermissions.fromString("rw-rw-r--"));
        why = gate.refusal(b);
        assertNotNull(why, "a group-writable certificate file");
        assertTrue(why.contains("the certificate file " + crt.toRealPath()
                + " is writable by group or others (rw-rw-r--)"), why);

        Files.setPosixFilePermissions(crt, PosixFilePermissions.fromString("rw-r--r--"));
        Files.setPosixFilePermissions(dir, PosixFilePermissions.fromString("rwxrwxrwx"));
        why = gate.refusal(b);
        assertNotNull(why, "a world-writable folder above the trust store");
        assertTrue(why.contains("the folder " + dir.toRealPath() + " above it is writable by group or others (0777)"),
                why);
        Files.setPosixFilePermissions(dir, PosixFilePermissions.fromString("rwx------"));
        assertNull(gate.refusal(b), "trusted again once fixed: the store is read for every decision");
    }

    @Test
    void aMissingOrBrokenTrustStoreTrustsNoSignature(@TempDir Path dir) throws Exception {
        byte[] signed = Signing.sign(dir, JarSignaturesTest.bundle("good"), one);
        String why = new CodeGate(List.of(), dir.resolve("nowhere"), log::add).refusal(installed("https://h/x.jar", signed));
        assertTrue(why.contains("signed by an unknown key: CN=Integrator One"), why);
        assertTrue(why.contains("(the trust store " + dir.resolve("nowhere") + " does not exist or is not a folder"),
                why);
        why = new CodeGate(List.of(), log::add).refusal(installed("https://h/x.jar", signed));
        assertTrue(why.contains("(no trust store is configured (framework property arflex.code.truststore))"), why);

        Path t = store(dir, one);
        Files.writeString(t.resolve("typo.crt"), "not a certificate");
        why = new CodeGate(List.of(), t, log::add).refusal(installed("https://h/x.jar", signed));
        assertNotNull(why);
        assertTrue(why.contains("the trust store " + t.toRealPath() + " is refused: typo.crt is not an X.509 certificate"),
                why);
    }

    /** The pinned path is unchanged: a jar whose SHA-256 matched the pin runs, signed or not. */
    @Test
    void thePinnedPathStillAdmitsUnsignedCode(@TempDir Path dir) throws Exception {
        CodeGate gate = new CodeGate(List.of(dir.resolve("cell")), store(dir, one), log::add);
        byte[] jar = JarSignaturesTest.bundle("good");
        Path f = Signing.write(dir.resolve("x.jar"), jar);
        VerifiedInstaller installer = new VerifiedInstaller(null, gate, log::add);
        installer.fetch(f.toUri().toString(), Services.sha256(jar));
        assertNull(gate.refusal(installed("https://h/x.jar", jar)), String.join("\n", log));
        assertTrue(log.get(log.size() - 1).contains("admitted: verified: " + f.toUri() + ", sha256 "), log.toString());
    }

    /** {@code arflex:deploy <url>} without a pin: only a jar signed by a trusted key is installed. */
    @Test
    void deployWithoutAPinInstallsOnlyATrustedSignedJar(@TempDir Path dir) throws Exception {
        CodeGate gate = new CodeGate(List.of(dir.resolve("cell")), store(dir, one), log::add);
        List<String> calls = new ArrayList<>();
        Bundle bundle = (Bundle) Proxy.newProxyInstance(Bundle.class.getClassLoader(), new Class<?>[] {Bundle.class},
                (p, m, a) -> {
                    calls.add(m.getName());
                    return m.getName().equals("getBundleId") ? 7L : null;
                });
        BundleContext ctx = (BundleContext) Proxy.newProxyInstance(BundleContext.class.getClassLoader(),
                new Class<?>[] {BundleContext.class}, (p, m, a) -> {
                    calls.add(m.getName());
                    return m.getName().equals("installBundle") ? bundle : null;
                });
        VerifiedInstaller installer = new VerifiedInstaller(ctx, gate, log::add);

        Path unsigned = Signing.write(dir.resolve("unsigned.jar"), JarSignaturesTest.bundle("x"));
        IllegalStateException e = assertThrows(IllegalStateException.class,
                () -> installer.deploy(unsigned.toUri().toString(), null));
        assertEquals("not installed: " + unsigned.toUri() + " has no pinned SHA-256 and is not signed by a trusted key: "
                + "unsigned: no signature file in META-INF; give its SHA-256 (deploy <url> <sha256>) or sign it with a "
                + "key of the trust store " + dir.resolve("trust"), e.getMessage());
        Path strange = Signing.write(dir.resolve("strange.jar"), Signing.sign(dir, JarSignaturesTest.bundle("x"), stranger));
        e = assertThrows(IllegalStateException.class, () -> installer.deploy(strange.toUri().toString(), null));
        assertTrue(e.getMessage().contains("signed by an unknown key: CN=Stranger"), e.getMessage());
        assertEquals(List.of(), calls, "nothing was installed");

        Path signed = Signing.write(dir.resolve("signed.jar"), Signing.sign(dir, JarSignaturesTest.bundle("x"), one));
        String out = installer.deploy(signed.toUri().toString(), null);
        assertEquals("Bundle ID: 7 (signed by CN=Integrator One, sha256 " + JarSignatures.fingerprint(one.cert()) + ")",
                out);
        assertEquals(List.of("getBundle", "installBundle", "start", "getBundleId", "getBundleId"), calls);
        assertFalse(log.isEmpty());
    }

    @Test
    void aSha256ThatIsNotOneIsStillRefused(@TempDir Path dir) throws Exception {
        VerifiedInstaller installer = new VerifiedInstaller(null, new CodeGate(List.of(), log::add), log::add);
        IllegalArgumentException e = assertThrows(IllegalArgumentException.class,
                () -> installer.deploy("https://h/x.jar", "abc"));
        assertTrue(e.getMessage().startsWith("deploy needs the jar's SHA-256 (64 hex digits) after its URL"),
                e.getMessage());
    }
}
