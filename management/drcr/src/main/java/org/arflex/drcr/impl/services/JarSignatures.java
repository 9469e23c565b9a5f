package org.arflex.drcr.impl.services;

import java.io.ByteArrayInputStream;
import java.io.ByteArrayOutputStream;
import java.io.IOException;
import java.nio.file.Files;
import java.nio.file.Path;
import java.security.CodeSigner;
import java.security.KeyStore;
import java.security.KeyStoreException;
import java.security.MessageDigest;
import java.security.NoSuchAlgorithmException;
import java.security.cert.Certificate;
import java.security.cert.CertificateEncodingException;
import java.security.cert.X509Certificate;
import java.time.Instant;
import java.util.ArrayList;
import java.util.Date;
import java.util.HexFormat;
import java.util.LinkedHashMap;
import java.util.LinkedHashSet;
import java.util.List;
import java.util.Locale;
import java.util.Map;
import java.util.Set;
import java.util.TreeMap;
import java.util.jar.Attributes;
import java.util.jar.JarEntry;
import java.util.jar.JarInputStream;
import java.util.jar.Manifest;
import java.util.zip.Deflater;
import java.util.zip.ZipEntry;
import java.util.zip.ZipOutputStream;

/**
 * Whether a jar is signed, entirely, by a key of the trust store (docs/DECISIONS.md D14). The
 * signatures are standard jar signatures ({@code jarsigner}) and are verified by the JDK
 * ({@link JarInputStream} with verification on); this class adds the rules the JDK leaves to
 * its caller:
 * <ul>
 * <li>every file entry except the signature files themselves ({@code META-INF/MANIFEST.MF},
 * {@code META-INF/*.SF|RSA|DSA|EC}, {@code META-INF/SIG-*}) is covered by a signature: an
 * entry added after signing is refused by name;</li>
 * <li>every entry is signed by the same signers, and every entry the signed manifest names is
 * present (nothing removed after signing);</li>
 * <li>every signature file covers the manifest's main attributes (the bundle's headers);</li>
 * <li>a modified entry (its digest no longer matches) is refused by name;</li>
 * <li>one of the signers' certificates is in the trust store, exactly (no chains: the trust
 * store pins the signing certificates themselves).</li>
 * </ul>
 * A certificate's validity dates are reported, not enforced (D14): the trust store decides, and a
 * key is withdrawn by removing its certificate.
 *
 * <p>The check runs on a jar's file entries by name, the same entries {@link ContentDigest}
 * covers, whether they come from a fetched jar or from the revision Felix installed: they are
 * written into a jar in the order the JDK verifier needs (manifest, signature files, the rest)
 * and read back with verification. A jar signature covers the bytes of the entries, not the
 * zip's layout, so this verifies exactly the content that runs.
 */
final class JarSignatures {

    /** Entries named in a refusal, at most. */
    private static final int NAMED = 3;

    /**
     * What the check said: accepted with the signer (subject, SHA-256 of its certificate) and a
     * note (empty, or about the certificate's dates), or refused with why.
     */
    record Verdict(boolean accepted, String signer, String fingerprint, String reason) {

        static Verdict refused(String reason) {
            return new Verdict(false, null, null, reason);
        }

        /** {@code signed by <subject>, sha256 <AB:CD:...>[; note]}, or the reason of a refusal. */
        String describe() {
            return !accepted ? reason
                    : "signed by " + signer + ", sha256 " + fingerprint + (reason.isEmpty() ? "" : "; " + reason);
        }
    }

    private JarSignatures() {
    }

    /** Checks a jar held in memory. */
    static Verdict check(byte[] jar, KeyStore trusted) {
        Map<String, byte[]> entries;
        try {
            entries = ContentDigest.entries(jar);
        } catch (IOException e) {
            return Verdict.refused("unreadable jar: " + e.getMessage());
        }
        return check(entries, trusted);
    }

    /** Checks a jar file. */
    static Verdict check(Path jar, KeyStore trusted) {
        try {
            BoundedJar reader = new BoundedJar(jar.toString());
            return check(reader.entries(reader.file(jar)), trusted);
        } catch (IOException e) {
            return Verdict.refused("cannot read " + jar + ": "
                    + (e instanceof java.nio.file.NoSuchFileException ? "no such file" : e.getMessage()));
        }
    }

    /** Checks a jar's file entries by name (directories left out). */
    static Verdict check(Map<String, byte[]> entries, KeyStore trusted) {
        String manifestName = null;
        List<String> sigFiles = new ArrayList<>();
        List<String> blocks = new ArrayList<>();
        for (String n : entries.keySet()) {
            if (n.equalsIgnoreCase("META-INF/MANIFEST.MF")) {
                if (manifestName != null) {
                    return Verdict.refused("refused: two manifests (" + manifestName + ", " + n + ")");
                }
                manifestName = n;
            } else if (signingFile(n)) {
                (n.toUpperCase(Locale.ROOT).endsWith(".SF") ? sigFiles : blocks).add(n);
            }
        }
        if (manifestName == null || sigFiles.isEmpty()) {
            return Verdict.refused("unsigned: " + (manifestName == null ? "no manifest" : "no signature file in META-INF"));
        }
        List<String> strays = strays(sigFiles, blocks);
        if (!strays.isEmpty()) {
            return Verdict.refused("refused: " + named(strays) + (strays.size() == 1 ? " is" : " are")
                    + " not covered by the signature (named like a signature file but not a signature file with its"
                    + " one block: added after signing?)");
        }
        for (String sf : sigFiles) {
            try {
                Attributes main = new Manifest(new ByteArrayInputStream(entries.get(sf))).getMainAttributes();
                if (main.keySet().stream().noneMatch(k -> k.toString().toUpperCase(Locale.ROOT)
                        .endsWith("-DIGEST-MANIFEST-MAIN-ATTRIBUTES"))) {
                    return Verdict.refused("refused: the signature file " + sf
                            + " does not cover the manifest's main attributes (sign it again with a current jarsigner)");
                }
            } catch (IOException e) {
                return Verdict.refused("refused: the signature file " + sf + " is unreadable: " + e.getMessage());
            }
        }

        Map<String, Set<CodeSigner>> signedBy = new LinkedHashMap<>();
        List<String> uncovered = new ArrayList<>();
        Manifest manifest;
        String current = null;
        try (JarInputStream in = new JarInputStream(new ByteArrayInputStream(ordered(entries, manifestName, sigFiles,
                blocks)), true)) {
            manifest = in.getManifest();
            JarEntry e;
            while ((e = in.getNextJarEntry()) != null) {
                current = e.getName();
                in.transferTo(java.io.OutputStream.nullOutputStream()); // bounded: the entries were read within limits
                if (signingFile(current)) {
                    continue;
                }
                CodeSigner[] s = e.getCodeSigners();
                if (s == null || s.length == 0) {
                    uncovered.add(current);
                } else {
                    signedBy.put(current, new LinkedHashSet<>(List.of(s)));
                }
            }
        } catch (SecurityException e) {
            return Verdict.refused("tampered: " + (current == null || signingFile(current)
                    ? "the signature " + (current == null ? "files do" : "file " + current + " does") + " not verify"
                    : "entry " + current + " does not match its signature") + " (" + e.getMessage() + ")");
        } catch (IOException e) {
            return Verdict.refused("unreadable jar: " + e.getMessage());
        }
        if (signedBy.isEmpty()) {
            return Verdict.refused("unsigned: no entry is covered by a valid signature");
        }
        if (!uncovered.isEmpty()) {
            return Verdict.refused("refused: " + named(uncovered) + (uncovered.size() == 1 ? " is" : " are")
                    + " not covered by the signature (added after signing?)");
        }
        var first = signedBy.entrySet().iterator().next();
        for (var e : signedBy.entrySet()) {
            if (!e.getValue().equals(first.getValue())) {
                return Verdict.refused("refused: signers differ between entries: " + first.getKey() + " is signed by "
                        + describe(first.getValue()) + ", " + e.getKey() + " by " + describe(e.getValue()));
            }
        }
        List<String> missing = new ArrayList<>();
        if (manifest != null) {
            for (var e : new TreeMap<>(manifest.getEntries()).entrySet()) {
                boolean digested = e.getValue().keySet().stream()
                        .anyMatch(k -> k.toString().toUpperCase(Locale.ROOT).endsWith("-DIGEST"));
                if (digested && !entries.containsKey(e.getKey())) {
                    missing.add(e.getKey());
                }
            }
        }
        if (!missing.isEmpty()) {
            return Verdict.refused("refused: " + named(missing) + (missing.size() == 1 ? " is" : " are")
                    + " in the signed manifest but missing from the jar (removed after signing?)");
        }
        for (CodeSigner s : first.getValue()) {
            X509Certificate c = signerCertificate(s);
            try {
                if (c != null && trusted != null && trusted.getCertificateAlias(c) != null) {
                    return new Verdict(true, c.getSubjectX500Principal().getName(), fingerprint(c), dates(c));
                }
            } catch (KeyStoreException e) {
                return Verdict.refused("the trust store is unusable: " + e.getMessage());
            }
        }
        return Verdict.refused("signed by an unknown key: " + describe(first.getValue())
                + " is not in the trust store");
    }

    /**
     * True for the files a jar signature consists of (not themselves signed), as the JDK counts
     * them: directly in META-INF, the manifest, {@code *.SF}, {@code *.RSA}, {@code *.DSA},
     * {@code *.EC} and {@code SIG-*}.
     */
    static boolean signingFile(String name) {
        String n = name.toUpperCase(Locale.ROOT);
        if (!n.startsWith("META-INF/") || n.indexOf('/', 9) >= 0) {
            return false;
        }
        n = n.substring(9);
        return n.equals("MANIFEST.MF") || n.endsWith(".SF") || n.endsWith(".RSA") || n.endsWith(".DSA")
                || n.endsWith(".EC") || n.startsWith("SIG-");
    }

    /**
     * The signature-like files that are not a signature (issue 30, finding 10): the JDK leaves
     * every {@code META-INF/*.SF|RSA|DSA|EC} and {@code SIG-*} out of its coverage, but only a
     * signature file with exactly one block of the same name, and that block, are a signature.
     */
    private static List<String> strays(List<String> sigFiles, List<String> blocks) {
        List<String> strays = new ArrayList<>();
        Map<String, List<String>> blocksOf = new LinkedHashMap<>();
        for (String b : blocks) {
            String base = base(b);
            if (base.startsWith("META-INF/SIG-")) {
                strays.add(b);
            } else {
                blocksOf.computeIfAbsent(base, k -> new ArrayList<>()).add(b);
            }
        }
        Set<String> bases = new LinkedHashSet<>();
        for (String sf : sigFiles) {
            List<String> own = blocksOf.get(base(sf));
            if (own == null || own.size() != 1 || !bases.add(base(sf))) {
                strays.add(sf);
            }
            if (own != null && own.size() > 1) {
                strays.addAll(own);
            }
        }
        for (var e : blocksOf.entrySet()) {
            if (!bases.contains(e.getKey()) && sigFiles.stream().noneMatch(sf -> base(sf).equals(e.getKey()))) {
                strays.addAll(e.getValue());
            }
        }
        return strays;
    }

    /** A name in upper case without its extension ({@code META-INF/ONE.SF}: {@code META-INF/ONE}). */
    private static String base(String name) {
        String n = name.toUpperCase(Locale.ROOT);
        int dot = n.lastIndexOf('.');
        return dot > n.lastIndexOf('/') ? n.substring(0, dot) : n;
    }

    /** The entries as a jar the JDK verifier reads: manifest, signature files, blocks, the rest. */
    private static byte[] ordered(Map<String, byte[]> entries, String manifest, List<String> sigFiles,
            List<String> blocks) throws IOException {
        ByteArrayOutputStream b = new ByteArrayOutputStream();
        try (ZipOutputStream z = new ZipOutputStream(b)) {
            z.setLevel(Deflater.NO_COMPRESSION);
            List<String> order = new ArrayList<>();
            order.add(manifest);
            order.addAll(sigFiles);
            order.addAll(blocks);
            for (String n : entries.keySet()) {
                if (!order.contains(n)) {
                    order.add(n);
                }
            }
            for (String n : order) {
                z.putNextEntry(new ZipEntry(n));
                z.write(entries.get(n));
                z.closeEntry();
            }
        }
        return b.toByteArray();
    }

    private static String named(List<String> names) {
        String s = String.join(", ", names.subList(0, Math.min(NAMED, names.size())));
        return names.size() == 1 ? "entry " + s
                : "entries " + s + (names.size() > NAMED ? " and " + (names.size() - NAMED) + " more" : "");
    }

    private static X509Certificate signerCertificate(CodeSigner s) {
        List<? extends Certificate> chain = s.getSignerCertPath().getCertificates();
        return !chain.isEmpty() && chain.get(0) instanceof X509Certificate x ? x : null;
    }

    private static String describe(Set<CodeSigner> signers) {
        List<String> l = new ArrayList<>();
        for (CodeSigner s : signers) {
            X509Certificate c = signerCertificate(s);
            l.add(c == null ? "(no X.509 certificate)" : c.getSubjectX500Principal().getName() + ", sha256 " + fingerprint(c));
        }
        return String.join(" and ", l);
    }

    /** SHA-256 of the certificate, as {@code keytool -printcert} prints it (AB:CD:...). */
    static String fingerprint(X509Certificate c) {
        try {
            byte[] d = MessageDigest.getInstance("SHA-256").digest(c.getEncoded());
            return HexFormat.ofDelimiter(":").withUpperCase().formatHex(d);
        } catch (NoSuchAlgorithmException | CertificateEncodingException e) {
            throw new IllegalStateException(e);
        }
    }

    /** Nothing, or a note that the certificate is outside its validity dates (not enforced: D14). */
    private static String dates(X509Certificate c) {
        Date now = Date.from(Instant.now());
        if (now.after(c.getNotAfter())) {
            return "its certificate expired on " + c.getNotAfter().toInstant()
                    + " (not enforced: remove it from the trust store to withdraw the key)";
        }
        if (now.before(c.getNotBefore())) {
            return "its certificate is valid only from " + c.getNotBefore().toInstant() + " (not enforced)";
        }
        return "";
    }
}
