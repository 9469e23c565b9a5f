package org.arflex.drcr.impl.services;

import java.io.ByteArrayInputStream;
import java.io.IOException;
import java.io.InputStream;
import java.net.URL;
import java.nio.ByteBuffer;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.security.MessageDigest;
import java.security.NoSuchAlgorithmException;
import java.util.Enumeration;
import java.util.HexFormat;
import java.util.Map;
import java.util.TreeMap;
import java.util.zip.ZipEntry;
import java.util.zip.ZipInputStream;
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

    /** The file entries of a jar held in memory, by name (what its digest covers). */
    static Map<String, byte[]> entries(byte[] jar) throws IOException {
        Map<String, byte[]> entries = new TreeMap<>();
        try (ZipInputStream in = new ZipInputStream(new ByteArrayInputStream(jar))) {
            ZipEntry e;
            while ((e = in.getNextEntry()) != null) {
                if (!e.isDirectory() && entries.put(e.getName(), in.readAllBytes()) != null) {
                    throw new IOException("entry " + e.getName() + " appears twice");
                }
            }
        }
        if (entries.isEmpty()) {
            throw new IOException("not a jar (no entries)");
        }
        return entries;
    }

    /** The digest of a jar file. */
    static String ofJar(Path jar) throws IOException {
        return ofJar(Files.readAllBytes(jar));
    }

    /** The digest of an installed bundle's current revision, from its entries. */
    static String ofBundle(Bundle b) throws IOException {
        return of(entries(b));
    }

    /** The file entries of an installed bundle's current revision, by name (what its digest covers). */
    static Map<String, byte[]> entries(Bundle b) throws IOException {
        Map<String, byte[]> entries = new TreeMap<>();
        collect(b, "/", entries);
        return entries;
    }

    private static void collect(Bundle b, String dir, Map<String, byte[]> into) throws IOException {
        Enumeration<String> paths = b.getEntryPaths(dir);
        if (paths == null) {
            return;
        }
        while (paths.hasMoreElements()) {
            String p = paths.nextElement();
            if (p.endsWith("/")) {
                collect(b, p, into);
                continue;
            }
            URL u = b.getEntry(p);
            if (u == null) {
                continue;
            }
            try (InputStream in = u.openStream()) {
                into.put(p.startsWith("/") ? p.substring(1) : p, in.readAllBytes());
            }
        }
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
