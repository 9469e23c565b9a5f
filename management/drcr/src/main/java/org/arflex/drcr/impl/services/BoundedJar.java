package org.arflex.drcr.impl.services;

import java.io.ByteArrayInputStream;
import java.io.FilterInputStream;
import java.io.IOException;
import java.io.InputStream;
import java.net.URL;
import java.nio.ByteBuffer;
import java.nio.ByteOrder;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.Enumeration;
import java.util.HashMap;
import java.util.Map;
import java.util.TreeMap;
import java.util.function.LongSupplier;
import java.util.function.Predicate;
import java.util.jar.Manifest;
import java.util.zip.ZipEntry;
import java.util.zip.ZipInputStream;
import org.osgi.framework.Bundle;

/**
 * Every read of a jar's entries by the DRCR (issue 30, finding 1: a zip bomb of 8 entries of
 * 1 GiB of zeros, 8 MB on disk, filled the heap and stalled the cell). Before anything is
 * inflated, the sizes and compression ratios the central directory declares are checked; then
 * every entry is inflated twice with hard limits: once counted only (nothing kept: a bomb is
 * refused having allocated nothing), once into an array of exactly the counted size. The
 * limits hold whatever the jar declares: the entry count, the bytes of one entry, of all, and
 * the ratio of inflated to compressed bytes once an entry passes {@link #RATIO_FREE_BYTES}. A
 * refusal is a {@link Refused} naming the jar, the entry and the limit. The entries kept of one
 * jar are at most {@link #MAX_TOTAL_BYTES}. Thread-safe (no state but the limits).
 */
final class BoundedJar {

    /** Most entries in a jar (the largest bundle the runtime ships has about 2000). */
    static final int MAX_ENTRIES = 10_000;
    /** Most bytes of one inflated entry (an RT executable: 24 MB today). */
    static final long MAX_ENTRY_BYTES = 64L << 20;
    /** Most bytes of all inflated entries of one jar. */
    static final long MAX_TOTAL_BYTES = 128L << 20;
    /** Most inflated bytes per compressed byte of an entry (deflated zeros reach about 1000). */
    static final int MAX_RATIO = 100;
    /** Entries up to this size are not held to {@link #MAX_RATIO} (a small text may compress well). */
    static final long RATIO_FREE_BYTES = 1L << 20;
    /** Largest jar file read (as {@link Fetch#MAX_JAR}). */
    static final long MAX_JAR_BYTES = Fetch.MAX_JAR;

    /** The limits a reader holds a jar to ({@link #DEFAULT} but in tests). */
    record Limits(int entries, long entryBytes, long totalBytes, int ratio, long ratioFreeBytes, long jarBytes) {
        static final Limits DEFAULT = new Limits(MAX_ENTRIES, MAX_ENTRY_BYTES, MAX_TOTAL_BYTES, MAX_RATIO,
                RATIO_FREE_BYTES, MAX_JAR_BYTES);
    }

    /** A jar refused by a limit: a verdict, not a read error (it is refused again if read again). */
    static final class Refused extends IOException {
        private static final long serialVersionUID = 1L;

        Refused(String message) {
            super(message);
        }
    }

    /** What a jar's entries are kept as when a caller does not keep their bytes. */
    static final byte[] NOT_KEPT = new byte[0];

    private static final String MANIFEST = "META-INF/MANIFEST.MF";
    /** Compressed bytes an inflater may have read ahead of what it gave (ZipInputStream's buffer). */
    private static final long READ_AHEAD = 1024;

    private final String jar;
    private final Limits limits;

    /** @param jar how the jar is named in a refusal (its location, file or bundle) */
    BoundedJar(String jar, Limits limits) {
        this.jar = jar;
        this.limits = limits;
    }

    BoundedJar(String jar) {
        this(jar, Limits.DEFAULT);
    }

    /** The bytes of a jar file, refused above {@link Limits#jarBytes} before they are read. */
    byte[] file(Path file) throws IOException {
        long size = Files.size(file);
        if (size > limits.jarBytes()) {
            throw refused(null, "is " + size + " bytes, over the limit of " + limits.jarBytes() + " bytes per jar");
        }
        return Files.readAllBytes(file);
    }

    /** The file entries of a jar held in memory, by name (directories left out), every entry kept. */
    Map<String, byte[]> entries(byte[] zip) throws IOException {
        return entries(zip, n -> true);
    }

    /**
     * The file entries of a jar held in memory, by name; an entry {@code keep} refuses is
     * counted and checked but kept as {@link #NOT_KEPT}.
     */
    Map<String, byte[]> entries(byte[] zip, Predicate<String> keep) throws IOException {
        if (zip.length > limits.jarBytes()) {
            throw refused(null, "is " + zip.length + " bytes, over the limit of " + limits.jarBytes() + " bytes per jar");
        }
        declared(zip);
        return read(visit -> walk(zip, visit), keep);
    }

    /** The file entries of an installed bundle's current revision, by name (its compressed sizes unknown). */
    Map<String, byte[]> entries(Bundle b) throws IOException {
        return read(visit -> walk(b, "/", visit), n -> true);
    }

    /** The entry {@code name} of a jar held in memory, as a stream that refuses past the limit of one entry. */
    InputStream open(byte[] zip, String name) throws IOException {
        ZipInputStream in = new ZipInputStream(new ByteArrayInputStream(zip));
        for (ZipEntry e = in.getNextEntry(); e != null; e = in.getNextEntry()) {
            if (e.getName().equals(name)) {
                return new FilterInputStream(in) {
                    private long n;

                    @Override
                    public int read() throws IOException {
                        byte[] one = new byte[1];
                        return read(one, 0, 1) < 0 ? -1 : one[0] & 0xff;
                    }

                    @Override
                    public int read(byte[] b, int off, int len) throws IOException {
                        int r = super.read(b, off, len);
                        n += Math.max(r, 0);
                        if (n > limits.entryBytes()) {
                            throw refused(name, "inflates past the limit of " + limits.entryBytes() + " bytes per entry");
                        }
                        return r;
                    }
                };
            }
        }
        in.close();
        throw new IOException(name + " is not in " + jar);
    }

    /** The manifest among a jar's entries (its name in any case, as the JDK finds it), or null. */
    static Manifest manifest(Map<String, byte[]> entries) throws IOException {
        for (var e : entries.entrySet()) {
            if (e.getKey().equalsIgnoreCase(MANIFEST)) {
                return new Manifest(new ByteArrayInputStream(e.getValue()));
            }
        }
        return null;
    }

    /** One entry as a walk gives it: its stream and how many compressed bytes it took so far (-1: unknown). */
    private interface Visit {
        void entry(String name, InputStream in, LongSupplier compressed) throws IOException;
    }

    private interface Walk {
        void each(Visit v) throws IOException;
    }

    /** Two passes: count (nothing kept), then keep exactly what was counted. */
    private Map<String, byte[]> read(Walk walk, Predicate<String> keep) throws IOException {
        Map<String, Long> sizes = new HashMap<>();
        long[] total = {0};
        byte[] buf = new byte[64 << 10];
        walk.each((name, in, compressed) -> {
            if (sizes.size() == limits.entries()) {
                throw refused(name, "is one entry more than the limit of " + limits.entries() + " entries per jar");
            }
            long n = count(name, in, compressed, total[0], buf);
            total[0] += n;
            if (sizes.put(name, n) != null) {
                throw new IOException("entry " + name + " appears twice in " + jar);
            }
        });
        Map<String, byte[]> entries = new TreeMap<>();
        walk.each((name, in, compressed) -> {
            Long size = sizes.get(name);
            if (size == null || entries.containsKey(name)) {
                throw new IOException(jar + " changed while it was read (entry " + name + ")");
            }
            if (!keep.test(name)) {
                entries.put(name, NOT_KEPT);
                return;
            }
            byte[] b = new byte[(int) (long) size];
            if (in.readNBytes(b, 0, b.length) != b.length || in.read() >= 0) {
                throw new IOException(jar + " changed while it was read (entry " + name + ")");
            }
            entries.put(name, b);
        });
        if (entries.size() != sizes.size()) {
            throw new IOException(jar + " changed while it was read");
        }
        return entries;
    }

    /** The inflated size of one entry, read in pieces and held to every limit as it grows. */
    private long count(String name, InputStream in, LongSupplier compressed, long before, byte[] buf)
            throws IOException {
        long n = 0;
        for (int r; (r = in.read(buf)) >= 0;) {
            n += r;
            if (n > limits.entryBytes()) {
                throw refused(name, "inflates past the limit of " + limits.entryBytes() + " bytes per entry");
            }
            if (before + n > limits.totalBytes()) {
                throw refused(name, "takes the jar past the limit of " + limits.totalBytes() + " inflated bytes per jar");
            }
            long c = compressed.getAsLong();
            if (c >= 0 && n > limits.ratioFreeBytes() && n > limits.ratio() * (c + READ_AHEAD)) {
                throw refused(name, "inflates " + n + " bytes from about " + c + " compressed, past the limit of "
                        + limits.ratio() + " to 1");
            }
        }
        return n;
    }

    /** The central directory's sizes and ratios, checked before anything is inflated (skipped when none is found). */
    private void declared(byte[] zip) throws Refused {
        ByteBuffer b = ByteBuffer.wrap(zip).order(ByteOrder.LITTLE_ENDIAN);
        int eocd = zip.length - 22;
        int floor = Math.max(0, zip.length - 22 - 0xffff);
        while (eocd >= floor && b.getInt(eocd) != 0x06054b50) {
            eocd--;
        }
        if (eocd < floor) {
            return; // no central directory: the stream's limits decide
        }
        int count = Short.toUnsignedInt(b.getShort(eocd + 10));
        if (count > limits.entries()) {
            throw refused(null, "declares " + count + " entries, over the limit of " + limits.entries()
                    + " entries per jar");
        }
        long at = Integer.toUnsignedLong(b.getInt(eocd + 16));
        long total = 0;
        for (int i = 0; i < count && at + 46 <= zip.length && b.getInt((int) at) == 0x02014b50; i++) {
            int p = (int) at;
            long csize = Integer.toUnsignedLong(b.getInt(p + 20));
            long size = Integer.toUnsignedLong(b.getInt(p + 24));
            int nameLen = Short.toUnsignedInt(b.getShort(p + 28));
            if (p + 46 + nameLen > zip.length) {
                return;
            }
            String name = new String(zip, p + 46, nameLen, java.nio.charset.StandardCharsets.UTF_8);
            if (size == 0xffffffffL || csize == 0xffffffffL) {
                throw refused(name, "declares a ZIP64 size, over the limit of " + limits.entryBytes() + " bytes per entry");
            }
            if (size > limits.entryBytes()) {
                throw refused(name, "declares " + size + " bytes, over the limit of " + limits.entryBytes()
                        + " bytes per entry");
            }
            total += size;
            if (total > limits.totalBytes()) {
                throw refused(name, "takes the declared size of the jar past the limit of " + limits.totalBytes()
                        + " inflated bytes per jar");
            }
            if (size > limits.ratioFreeBytes() && size > limits.ratio() * Math.max(csize, 1)) {
                throw refused(name, "declares " + size + " bytes from " + csize + " compressed, over the limit of "
                        + limits.ratio() + " to 1");
            }
            at += 46L + nameLen + Short.toUnsignedInt(b.getShort(p + 30)) + Short.toUnsignedInt(b.getShort(p + 32));
        }
    }

    private Refused refused(String entry, String what) {
        return new Refused(jar + (entry == null ? " " : ": entry " + entry + " ") + what
                + " (refused by the code gate's bounded reader, D78)");
    }

    /** The file entries of a zip held in memory, with the compressed bytes each took. */
    private static void walk(byte[] zip, Visit visit) throws IOException {
        long[] consumed = {0};
        InputStream counting = new FilterInputStream(new ByteArrayInputStream(zip)) {
            @Override
            public int read() throws IOException {
                int r = super.read();
                consumed[0] += r < 0 ? 0 : 1;
                return r;
            }

            @Override
            public int read(byte[] b, int off, int len) throws IOException {
                int r = super.read(b, off, len);
                consumed[0] += Math.max(r, 0);
                return r;
            }
        };
        try (ZipInputStream in = new ZipInputStream(counting)) {
            for (ZipEntry e = in.getNextEntry(); e != null; e = in.getNextEntry()) {
                if (!e.isDirectory()) {
                    long start = consumed[0];
                    visit.entry(e.getName(), in, () -> consumed[0] - start);
                }
            }
        }
    }

    /** The file entries of a bundle, by path without the leading slash. */
    private static void walk(Bundle b, String dir, Visit visit) throws IOException {
        Enumeration<String> paths = b.getEntryPaths(dir);
        if (paths == null) {
            return;
        }
        while (paths.hasMoreElements()) {
            String p = paths.nextElement();
            if (p.endsWith("/")) {
                walk(b, p, visit);
                continue;
            }
            URL u = b.getEntry(p);
            if (u == null) {
                continue;
            }
            try (InputStream in = u.openStream()) {
                visit.entry(p.startsWith("/") ? p.substring(1) : p, in, () -> -1);
            }
        }
    }
}
