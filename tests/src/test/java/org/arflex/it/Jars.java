package org.arflex.it;

import java.io.IOException;
import java.io.InputStream;
import java.io.OutputStream;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.security.MessageDigest;
import java.util.HexFormat;
import java.util.function.UnaryOperator;
import java.util.jar.JarEntry;
import java.util.jar.JarInputStream;
import java.util.jar.JarOutputStream;
import java.util.jar.Manifest;

/** Makes variants of a component bundle: the same jar with its contract rewritten. */
public final class Jars {

    private Jars() {
    }

    /** Copies {@code jar} to {@code out}, passing every OSGI-INF/arflex/*.xml through {@code edit}. */
    public static Path withContract(Path jar, Path out, UnaryOperator<String> edit) throws IOException {
        try (InputStream fin = Files.newInputStream(jar); JarInputStream in = new JarInputStream(fin)) {
            Manifest m = in.getManifest();
            try (OutputStream fout = Files.newOutputStream(out); JarOutputStream o = new JarOutputStream(fout, m)) {
                JarEntry e;
                while ((e = in.getNextJarEntry()) != null) {
                    byte[] data = in.readAllBytes();
                    if (e.getName().startsWith("OSGI-INF/arflex/") && e.getName().endsWith(".xml")) {
                        data = edit.apply(new String(data, StandardCharsets.UTF_8)).getBytes(StandardCharsets.UTF_8);
                    }
                    o.putNextEntry(new JarEntry(e.getName()));
                    o.write(data);
                    o.closeEntry();
                }
            }
        }
        return out;
    }

    static String sha256(Path p) throws Exception {
        return HexFormat.of().formatHex(MessageDigest.getInstance("SHA-256").digest(Files.readAllBytes(p)));
    }
}
