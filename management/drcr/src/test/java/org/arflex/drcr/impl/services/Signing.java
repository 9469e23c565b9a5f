package org.arflex.drcr.impl.services;

import java.io.ByteArrayInputStream;
import java.io.ByteArrayOutputStream;
import java.io.IOException;
import java.io.InputStream;
import java.io.OutputStream;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.security.KeyStore;
import java.security.PrivateKey;
import java.security.cert.CertPath;
import java.security.cert.CertificateFactory;
import java.security.cert.X509Certificate;
import java.util.ArrayList;
import java.util.Arrays;
import java.util.Base64;
import java.util.List;
import java.util.Map;
import java.util.function.UnaryOperator;
import java.util.zip.ZipEntry;
import java.util.zip.ZipFile;
import java.util.zip.ZipInputStream;
import java.util.zip.ZipOutputStream;
import jdk.security.jarsigner.JarSigner;

/**
 * Keys, signed jars and trust stores made at test time: a key pair and self-signed certificate
 * by the JDK's {@code keytool}, signatures by the JDK's {@link JarSigner} (what {@code jarsigner}
 * runs), certificates written as {@code keytool -exportcert -rfc} writes them.
 */
final class Signing {

    static final char[] PASSWORD = "test-only".toCharArray();

    /** A signing key and its certificate. */
    record Key(String alias, PrivateKey key, CertPath path, X509Certificate cert) {
    }

    private Signing() {
    }

    /** Makes a key with keytool ({@code extra}: more keytool options, e.g. dates). */
    static Key key(Path dir, String alias, String dname, String... extra) throws Exception {
        Path store = dir.resolve(alias + ".p12");
        List<String> cmd = new ArrayList<>(List.of(Path.of(System.getProperty("java.home"), "bin", "keytool").toString(),
                "-genkeypair", "-keyalg", "EC", "-groupname", "secp256r1", "-alias", alias, "-dname", dname,
                "-keystore", store.toString(), "-storetype", "PKCS12", "-storepass", new String(PASSWORD)));
        cmd.addAll(Arrays.asList(extra));
        Process p = new ProcessBuilder(cmd).redirectErrorStream(true).start();
        String out = new String(p.getInputStream().readAllBytes(), StandardCharsets.UTF_8);
        if (p.waitFor() != 0) {
            throw new IllegalStateException("keytool failed: " + out);
        }
        KeyStore ks = KeyStore.getInstance("PKCS12");
        try (InputStream in = Files.newInputStream(store)) {
            ks.load(in, PASSWORD);
        }
        CertPath path = CertificateFactory.getInstance("X.509")
                .generateCertPath(Arrays.asList(ks.getCertificateChain(alias)));
        return new Key(alias, (PrivateKey) ks.getKey(alias, PASSWORD), path, (X509Certificate) path.getCertificates().get(0));
    }

    /** The jar signed by {@code k}, as jarsigner signs it (signature files named after its alias). */
    static byte[] sign(Path dir, byte[] jar, Key k) throws Exception {
        Path in = Files.createTempFile(dir, "unsigned", ".jar");
        Files.write(in, jar);
        JarSigner signer = new JarSigner.Builder(k.key(), k.path()).digestAlgorithm("SHA-256")
                .signerName(k.alias().toUpperCase(java.util.Locale.ROOT)).build();
        ByteArrayOutputStream out = new ByteArrayOutputStream();
        try (ZipFile z = new ZipFile(in.toFile())) {
            signer.sign(z, out);
        }
        return out.toByteArray();
    }

    /** The certificate in PEM, as {@code keytool -exportcert -rfc} writes it. */
    static String pem(X509Certificate c) throws Exception {
        return "-----BEGIN CERTIFICATE-----\n" + Base64.getMimeEncoder(64, "\n".getBytes(StandardCharsets.US_ASCII))
                .encodeToString(c.getEncoded()) + "\n-----END CERTIFICATE-----\n";
    }

    /** A trust store folder (0755, files 0644, as umask 022 makes them) holding these certificates. */
    static Path trustStore(Path dir, Key... trusted) throws Exception {
        Path t = Files.createDirectories(dir.resolve("trust"));
        for (Key k : trusted) {
            Files.writeString(t.resolve(k.path().getCertificates().get(0).hashCode() + ".crt"), pem(k.cert()));
        }
        return t;
    }

    /** The jar with entries rewritten: {@code edit} gets and returns the entries in order. */
    static byte[] rewrite(byte[] jar, UnaryOperator<List<Map.Entry<String, byte[]>>> edit) throws IOException {
        List<Map.Entry<String, byte[]>> entries = new ArrayList<>();
        try (ZipInputStream in = new ZipInputStream(new ByteArrayInputStream(jar))) {
            ZipEntry e;
            while ((e = in.getNextEntry()) != null) {
                entries.add(Map.entry(e.getName(), in.readAllBytes()));
            }
        }
        ByteArrayOutputStream b = new ByteArrayOutputStream();
        try (ZipOutputStream z = new ZipOutputStream(b)) {
            for (var e : edit.apply(entries)) {
                z.putNextEntry(new ZipEntry(e.getKey()));
                z.write(e.getValue());
                z.closeEntry();
            }
        }
        return b.toByteArray();
    }

    /** Writes bytes to a file and returns it. */
    static Path write(Path file, byte[] bytes) throws IOException {
        try (OutputStream out = Files.newOutputStream(file)) {
            out.write(bytes);
        }
        return file;
    }
}
