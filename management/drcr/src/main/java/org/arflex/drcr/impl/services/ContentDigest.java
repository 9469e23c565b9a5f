package org.arflex.drcr.impl.services;

import java.io.IOException;
import java.nio.ByteBuffer;
import java.nio.charset.StandardCharsets;
import java.nio.file.Path;
import java.security.MessageDigest;
import java.security.NoSuchAlgorithmException;
import java.util.HexFormat;
import java.util.Map;
import org.osgi.framework.Bundle;

/**
 * One digest of a bundle's content that is the same whether it is read from the jar's bytes or
 * from the bundle Felix installed (Felix keeps its own copy and gives only its entries): SHA-256
 * over every file entry, sorted by name, each as its name, a zero byte, its length (8 bytes) and
 * its bytes. Directories do not count (a jar may or may not list them).
 */
final class ContentDigest {

    private ContentDigest() {
    }

    /** The digest of a jar held in memory. */
    static String ofJar(byte[] jar) throws IOException {
        return of(entries(jar));
    }

    /** The file entries of a jar held in memory, by name (what its digest covers), read within limits. */
    static Map<String, byte[]> entries(byte[] jar) throws IOException {
        return entries("the jar", jar);
    }

    /** As {@link #entries(byte[])}, the jar named {@code name} in a refusal. */
    static Map<String, byte[]> entries(String name, byte[] jar) throws IOException {
        Map<String, byte[]> entries = new BoundedJar(name).entries(jar);
        if (entries.isEmpty()) {
            throw new IOException("not a jar (no entries)");
        }
        return entries;
    }

    /** The digest of a jar file. */
    static String ofJar(Path jar) throws IOException {
        BoundedJar reader = new BoundedJar(jar.toString());
        return of(reader.entries(reader.file(jar)));
    }

    /** The file entries of an installed bundle's current revision, by name (what its digest covers). */
    static Map<String, byte[]> entries(Bundle b) throws IOException {
        return new BoundedJar("bundle " + b.getBundleId() + " (" + b.getLocation() + ")").entries(b);
    }

    static String of(Map<String, byte[]> sortedEntries) {
        MessageDigest md;
        try {
            md = MessageDigest.getInstance("SHA-256");
        } catch (NoSuchAlgorithmException e) {
            throw new IllegalStateException(e);
        }
        for (var e : sortedEntries.entrySet()) {
            md.update(e.getKey().getBytes(StandardCharsets.UTF_8));
            md.update((byte) 0);
            md.update(ByteBuffer.allocate(8).putLong(e.getValue().length).array());
            update(md, e.getValue());
        }
        return HexFormat.of().formatHex(md.digest());
    }

    /**
     * Hashes in 64 KiB pieces: one call over megabytes is a loop without a safepoint poll, and
     * on a busy machine every other JVM thread (the runtime heartbeat's included) then waits at
     * the next safepoint for as long as that thread is kept off the CPU.
     */
    static void update(java.security.MessageDigest md, byte[] data) {
        for (int off = 0; off < data.length; off += 64 << 10) {
            md.update(data, off, Math.min(64 << 10, data.length - off));
        }
    }
}
