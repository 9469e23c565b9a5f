package org.arflex.drcr.impl.services;

import static org.junit.jupiter.api.Assertions.assertArrayEquals;
import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.ByteArrayOutputStream;
import java.io.IOException;
import java.io.InputStream;
import java.util.Map;
import java.util.Random;
import java.util.zip.ZipEntry;
import java.util.zip.ZipOutputStream;
import org.junit.jupiter.api.Test;

/**
 * Each limit of the bounded reader (D78), as the central directory declares it (refused before
 * anything is inflated) and as the entries inflate when the directory lies or is missing.
 */
class BoundedJarTest {

    private static final int NONE = Integer.MAX_VALUE;

    /** A jar of entries {@code e-<i>}, each of {@code sizes[i]} random (incompressible) bytes. */
    private static byte[] random(int... sizes) throws IOException {
        Random r = new Random(30);
        ByteArrayOutputStream b = new ByteArrayOutputStream();
        try (ZipOutputStream z = new ZipOutputStream(b)) {
            for (int i = 0; i < sizes.length; i++) {
                byte[] d = new byte[sizes[i]];
                r.nextBytes(d);
                z.putNextEntry(new ZipEntry("e-" + i));
                z.write(d);
            }
        }
        return b.toByteArray();
    }

    /** Refused as declared, as inflated behind lying sizes, and without a central directory. */
    private static void refusedEveryWay(BoundedJar.Limits limits, byte[] jar, String entry, String limit) {
        for (byte[] j : new byte[][] {jar, Bombs.lying(jar, 10), Bombs.headless(jar)}) {
            IOException e = assertThrows(BoundedJar.Refused.class, () -> new BoundedJar("x.jar", limits).entries(j));
            assertTrue(e.getMessage().startsWith("x.jar: entry " + entry + " ") && e.getMessage().contains(limit),
                    e.getMessage());
        }
    }

    @Test
    void tooManyEntriesAreRefused() throws IOException {
        byte[] jar = random(10, 10, 10, 10);
        var limits = new BoundedJar.Limits(3, NONE, NONE, NONE, 0, NONE);
        IOException declared = assertThrows(BoundedJar.Refused.class, () -> new BoundedJar("x.jar", limits).entries(jar));
        assertEquals("x.jar declares 4 entries, over the limit of 3 entries per jar (refused by the code gate's "
                + "bounded reader, D78)", declared.getMessage());
        IOException streamed = assertThrows(BoundedJar.Refused.class,
                () -> new BoundedJar("x.jar", limits).entries(Bombs.headless(jar)));
        assertTrue(streamed.getMessage().startsWith("x.jar: entry e-3 is one entry more than the limit of 3 entries"),
                streamed.getMessage());
    }

    @Test
    void anEntryLargerThanItsLimitIsRefused() throws IOException {
        refusedEveryWay(new BoundedJar.Limits(10, 1 << 20, NONE, NONE, 0, NONE), random(1000, 2 << 20), "e-1",
                "limit of 1048576 bytes per entry");
    }

    @Test
    void entriesLargerTogetherThanTheJarsLimitAreRefused() throws IOException {
        refusedEveryWay(new BoundedJar.Limits(10, NONE, 5 << 19, NONE, 0, NONE), random(1 << 20, 1 << 20, 1 << 20),
                "e-2", "limit of 2621440 inflated bytes per jar");
    }

    @Test
    void anEntryInflatingPastTheRatioIsRefused() throws IOException {
        refusedEveryWay(BoundedJar.Limits.DEFAULT, Bombs.zeros(1, 8 << 20), "bomb-0", "limit of 100 to 1");
    }

    @Test
    void aJarLargerThanItsLimitIsRefusedUnread() throws IOException {
        var limits = new BoundedJar.Limits(10, NONE, NONE, NONE, 0, 1000);
        IOException e = assertThrows(BoundedJar.Refused.class, () -> new BoundedJar("x.jar", limits)
                .entries(random(2000)));
        assertTrue(e.getMessage().contains("over the limit of 1000 bytes per jar"), e.getMessage());
    }

    @Test
    void aJarWithinTheLimitsIsReadWholeAndAnEntryStreamsWithinItsLimit() throws IOException {
        byte[] jar = random(100, 3 << 20, 0);
        Map<String, byte[]> entries = new BoundedJar("x.jar").entries(jar);
        assertEquals(java.util.List.of("e-0", "e-1", "e-2"), java.util.List.copyOf(entries.keySet()));
        assertEquals(3 << 20, entries.get("e-1").length);
        try (InputStream in = new BoundedJar("x.jar").open(jar, "e-1")) {
            assertArrayEquals(entries.get("e-1"), in.readAllBytes());
        }
        var small = new BoundedJar.Limits(10, 1 << 20, NONE, NONE, 0, NONE);
        IOException e = assertThrows(BoundedJar.Refused.class, () -> {
            try (InputStream in = new BoundedJar("x.jar", small).open(jar, "e-1")) {
                in.readAllBytes();
            }
        });
        assertTrue(e.getMessage().startsWith("x.jar: entry e-1 inflates past the limit of 1048576 bytes per entry"),
                e.getMessage());
        assertEquals(0, new BoundedJar("x.jar").entries(jar, n -> !n.equals("e-1")).get("e-1").length, "not kept");
    }

    @Test
    void aJarWithinTheLimitsIsKeptOnceItsInflatedSizeNoMore(@org.junit.jupiter.api.io.TempDir java.nio.file.Path dir)
            throws IOException {
        // an RT executable of 24 MiB (the largest today) and a contract: what a reading keeps is measured
        int exe = 24 << 20;
        java.nio.file.Path jar = java.nio.file.Files.write(dir.resolve("x.jar"), random(exe, 3000));
        long size = java.nio.file.Files.size(jar);
        Bombs.Measured<Map<String, byte[]>> m = Bombs.allocation(() -> {
            BoundedJar r = new BoundedJar(jar.toString());
            return r.entries(r.file(jar));
        });
        assertEquals(exe, m.value().get("e-0").length);
        System.out.println("a jar of " + (size >> 10) + " KiB inflating to " + ((exe + 3000) >> 10) + " KiB read having"
                + " allocated " + (m.allocated() >> 10) + " KiB");
        assertTrue(m.allocated() < size + exe + (4 << 20), "allocated " + (m.allocated() >> 10) + " KiB");
    }
}
