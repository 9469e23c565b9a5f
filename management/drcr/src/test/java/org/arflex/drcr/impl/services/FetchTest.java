package org.arflex.drcr.impl.services;

import static org.junit.jupiter.api.Assertions.assertArrayEquals;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.net.ServerSocket;
import java.net.Socket;
import java.net.URI;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.List;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;

/** Issue 16 finding 4: {@code update <id> ftp://...} against a silent server held the shell 2 min 20 s. */
class FetchTest {

    @Test
    void onlyHttpsAndFileAreOpened() {
        for (String u : List.of("ftp://127.0.0.1:1/x.jar", "http://127.0.0.1:1/x.jar", "jar:file:/tmp/a.jar!/x.jar")) {
            IOException e = assertThrows(IOException.class, () -> Fetch.read(URI.create(u)));
            assertTrue(e.getMessage().contains("only https and file URLs"), e.getMessage());
        }
    }

    @Test
    void aServerThatNeverAnswersTimesOut() throws Exception {
        try (ServerSocket server = new ServerSocket(0)) {
            Thread t = new Thread(() -> {
                try (Socket s = server.accept()) {
                    Thread.sleep(10_000);
                } catch (IOException | InterruptedException ignored) {
                    // closed by the test
                }
            });
            t.setDaemon(true);
            t.start();
            long t0 = System.nanoTime();
            assertThrows(IOException.class,
                    () -> Fetch.read(URI.create("https://127.0.0.1:" + server.getLocalPort() + "/x.jar"), 300, 300));
            long ms = (System.nanoTime() - t0) / 1_000_000;
            assertTrue(ms < 5_000, "took " + ms + " ms");
            t.interrupt();
        }
    }

    @Test
    void aFileIsReadWhole(@TempDir Path dir) throws IOException {
        Path f = dir.resolve("x.jar");
        byte[] b = new byte[100_000];
        b[99_999] = 7;
        Files.write(f, b);
        assertArrayEquals(b, Fetch.read(f.toUri()));
    }

    @Test
    void aFileLargerThanTheLimitIsRefusedUnread(@TempDir Path dir) throws IOException {
        Path f = dir.resolve("big.jar");
        try (java.io.RandomAccessFile r = new java.io.RandomAccessFile(f.toFile(), "rw")) {
            r.setLength(Fetch.MAX_JAR + 1L); // sparse: nothing to read but zeros
        }
        Bombs.Measured<byte[]> m = Bombs.allocation(() -> Fetch.read(f.toUri()));
        assertTrue(m.thrown() instanceof IOException && m.thrown().getMessage().equals(
                (Fetch.MAX_JAR + 1L) + " bytes, larger than the limit of " + Fetch.MAX_JAR + " bytes per jar"),
                String.valueOf(m.thrown()));
        assertTrue(m.allocated() < 1 << 20, "allocated " + m.allocated());
    }
}
