package org.arflex.drcr.impl.services;

import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertNotNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.List;
import org.junit.jupiter.api.BeforeAll;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;

/**
 * Issue 30, finding 1: a zip bomb (8 entries of 64 MiB of zeros, 0.5 MB on disk) is refused
 * cheaply on every path that reads a jar, naming the entry and the limit, and its verification
 * allocates a bounded amount of heap, not what the bomb inflates to.
 */
class JarBombTest {

    /** Heap a refusal of the bomb may allocate on the reading thread. */
    private static final long CHEAP = 16L << 20;

    static byte[] bomb;

    @BeforeAll
    static void makeBomb() throws IOException {
        bomb = Bombs.zeros(8, 64L << 20);
    }

    private static void refusedCheaply(Bombs.Measured<?> m, String what) {
        assertNotNull(m.thrown(), what + " read the bomb without a refusal");
        String msg = m.thrown().getMessage();
        assertTrue(msg.contains("bomb-0") && msg.contains("limit"), what + ": " + msg);
        assertTrue(m.allocated() < CHEAP, what + " allocated " + (m.allocated() >> 20) + " MiB");
        System.out.println("bomb refused (" + what + ") having allocated " + (m.allocated() >> 10) + " KiB: " + msg);
    }

    @Test
    void theContentDigestRefusesABombWithinABoundedHeap() {
        refusedCheaply(Bombs.allocation(() -> ContentDigest.entries(bomb)), "declared sizes");
        // sizes that lie in the central directory: the inflated bytes are counted as they come
        refusedCheaply(Bombs.allocation(() -> ContentDigest.entries(Bombs.lying(bomb, 1000))), "lying sizes");
    }

    @Test
    void theSignatureCheckRefusesABombWithinABoundedHeap() {
        Bombs.Measured<JarSignatures.Verdict> m = Bombs.allocation(() -> JarSignatures.check(Bombs.lying(bomb, 1000),
                null));
        assertFalse(m.value().accepted());
        assertTrue(m.value().reason().contains("bomb-0") && m.value().reason().contains("limit"), m.value().reason());
        assertTrue(m.allocated() < CHEAP, "allocated " + (m.allocated() >> 20) + " MiB");
    }

    @Test
    void aBombInATrustedFolderIsRefusedWithinABoundedHeap(@TempDir Path dir) throws Exception {
        Path f = Files.write(dir.resolve("bomb.jar"), bomb);
        CodeGate gate = new CodeGate(List.of(dir), s -> { });
        Bombs.Measured<CodeGate.Decision> m = Bombs.allocation(() -> gate.decide(f.toUri().toString(), "0".repeat(64)));
        assertFalse(m.value().admitted());
        assertTrue(m.value().reason().contains("bomb-0") && m.value().reason().contains("limit"), m.value().reason());
        assertTrue(m.allocated() < CHEAP, "allocated " + (m.allocated() >> 20) + " MiB");
    }

    @Test
    void anInstalledBombIsRefusedWithinABoundedHeap() {
        // install + start of the bomb: the code gate reads the entries Felix gives, 8 of 1 GiB
        CodeGate gate = new CodeGate(List.of(), s -> { });
        Bombs.Measured<String> m = Bombs.allocation(() -> gate.refusal(Bombs.installed(8, 1L << 30)));
        assertNotNull(m.value(), "the bomb was admitted");
        assertTrue(m.value().contains("bomb-0") && m.value().contains("limit"), m.value());
        assertTrue(m.allocated() < CHEAP, "allocated " + (m.allocated() >> 20) + " MiB");
        System.out.println("installed bomb refused having allocated " + (m.allocated() >> 10) + " KiB: " + m.value());
    }
}
