package org.arflex.webconsole;

import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.security.MessageDigest;
import java.util.HexFormat;
import java.util.function.UnaryOperator;

/** The bundles the console tests install, and the variants they make of them. */
final class ConsoleJars {
    private ConsoleJars() {
    }

    /** The built sample bundle {@code sample-<which>}; fails when it is not built. */
    static Path sample(String which) {
        Path p = org.arflex.it.Components.jar("sample-" + which);
        assertTrue(Files.isRegularFile(p), "sample bundle " + which + " not built: " + p);
        return p;
    }

    static String sha256(Path p) throws IOException {
        try {
            return HexFormat.of().formatHex(MessageDigest.getInstance("SHA-256").digest(Files.readAllBytes(p)));
        } catch (java.security.NoSuchAlgorithmException e) {
            throw new IllegalStateException(e);
        }
    }

    /**
     * Copies {@code jar} to {@code out} with every OSGI-INF/arflex/*.xml contract passed through
     * {@code edit}, which must change it (an edit that matches nothing is a broken test).
     */
    static Path withContract(Path jar, Path out, UnaryOperator<String> edit) throws IOException {
        Files.createDirectories(out.getParent());
        return org.arflex.it.Jars.withContract(jar, out, xml -> {
            String edited = edit.apply(xml);
            assertFalse(xml.equals(edited), "the edit changed nothing in the contract of " + jar.getFileName());
            return edited;
        });
    }

    /** A copy of {@code component}'s bundle in {@code dir} whose contract says {@code version}: the same executable. */
    static Path version(Path dir, String component, String version) throws IOException {
        Path in = org.arflex.it.Components.jar(component);
        Path out = dir.resolve(component + "-" + version + ".jar");
        String entry = "OSGI-INF/arflex/" + component + ".xml";
        boolean found = false;
        try (java.util.zip.ZipFile z = new java.util.zip.ZipFile(in.toFile());
                java.util.zip.ZipOutputStream zo = new java.util.zip.ZipOutputStream(Files.newOutputStream(out))) {
            for (java.util.zip.ZipEntry e : java.util.Collections.list(z.entries())) {
                byte[] b = z.getInputStream(e).readAllBytes();
                if (e.getName().equals(entry)) {
                    String xml = new String(b, StandardCharsets.UTF_8);
                    String now = xml.replaceFirst("name=\"" + component + "\" version=\"[^\"]+\"",
                            "name=\"" + component + "\" version=\"" + version + "\"");
                    assertFalse(now.equals(xml), "the contract's version was not rewritten");
                    b = now.getBytes(StandardCharsets.UTF_8);
                    found = true;
                }
                zo.putNextEntry(new java.util.zip.ZipEntry(e.getName()));
                zo.write(b);
                zo.closeEntry();
            }
        }
        assertTrue(found, entry + " in " + in);
        return out;
    }

    /** A cell bundle: from the assembly's cell/, else as built in bundles/<module>/target. */
    static Path cellJar(String module, String artifact) {
        Path assembled = Path.of(System.getProperty("arflex.runtime.dir", "../management/runtime/target/arflex-runtime"))
                .toAbsolutePath().normalize().resolve("cell").resolve(artifact + ".jar");
        if (Files.isRegularFile(assembled)) {
            return assembled;
        }
        Path root = Path.of(System.getProperty("arflex.root", "..")).toAbsolutePath().normalize();
        Path built = root.resolve("bundles").resolve(module).resolve("target").resolve(artifact + "-0.1.0-SNAPSHOT.jar");
        assertTrue(Files.isRegularFile(built), artifact + " is neither in the runtime assembly (" + assembled
                + ") nor built (" + built + ")");
        return built;
    }
}
