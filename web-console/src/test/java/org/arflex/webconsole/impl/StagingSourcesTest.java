package org.arflex.webconsole.impl;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import com.sun.net.httpserver.HttpServer;
import java.io.IOException;
import java.io.OutputStream;
import java.net.InetAddress;
import java.net.InetSocketAddress;
import java.net.URI;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.security.MessageDigest;
import java.util.HexFormat;
import java.util.List;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;

/**
 * Where stage-url may read from (issue 16, finding 8): a file: URL only inside a configured
 * folder (none configured: no file: URL at all), and never through a redirect. A refusal must
 * not reveal anything about the file, such as its SHA-256.
 */
class StagingSourcesTest {
    @TempDir
    Path dir;

    private static String sha(byte[] b) throws Exception {
        return HexFormat.of().formatHex(MessageDigest.getInstance("SHA-256").digest(b));
    }

    private Path secret() throws IOException {
        return Files.writeString(dir.resolve("secret.txt"), "root:x:0:0:root:/root:/bin/bash\n");
    }

    private HttpError stage(String url, StagingSources sources) {
        String pin = "0".repeat(64);
        return assertThrows(HttpError.class, () -> Artifacts.fetch(Artifacts.checkUrl(url, pin), pin,
                dir.resolve("staging"), sources));
    }

    @Test
    void withNoFolderConfiguredEveryFileUrlIsRefused() throws Exception {
        Path secret = secret();
        HttpError e = stage(secret.toUri().toString(), StagingSources.parse(null));
        assertEquals(400, e.status);
        assertTrue(e.getMessage().contains("file: URLs are refused") && e.getMessage().contains(StagingSources.PROPERTY),
                e.getMessage());
        assertFalse(e.getMessage().contains(sha(Files.readAllBytes(secret))), "the file's digest leaked");
        assertTrue(stage("file:/etc/passwd", StagingSources.parse("  ")).getMessage().contains("file: URLs are refused"));
    }

    @Test
    void aFileOutsideTheConfiguredFoldersIsRefusedWithoutSayingWhetherItExists() throws Exception {
        Path allowed = Files.createDirectories(dir.resolve("allowed"));
        Path secret = secret();
        StagingSources sources = StagingSources.parse(allowed + ", " + dir.resolve("other"));
        for (String url : List.of(secret.toUri().toString(), allowed.toUri() + "../secret.txt",
                allowed.toUri() + "..%2Fsecret.txt", "file:/etc/passwd", dir.resolve("missing.jar").toUri().toString())) {
            HttpError e = stage(url, sources);
            assertEquals(400, e.status, url);
            assertTrue(e.getMessage().contains("outside the folders") || e.getMessage().contains("not a file path"),
                    url + ": " + e.getMessage());
            assertFalse(e.getMessage().contains(sha(Files.readAllBytes(secret))), "the file's digest leaked");
        }
    }

    @Test
    void aSymbolicLinkOutOfAFolderIsRefused() throws Exception {
        Path allowed = Files.createDirectories(dir.resolve("allowed"));
        Path secret = secret();
        Path link = Files.createSymbolicLink(allowed.resolve("x.jar"), secret);
        HttpError e = stage(link.toUri().toString(), StagingSources.parse(allowed.toString()));
        assertTrue(e.getMessage().contains("outside the folders"), e.getMessage());
    }

    @Test
    void aFileInsideAFolderIsRead() throws Exception {
        Path allowed = Files.createDirectories(dir.resolve("allowed"));
        Path notAJar = Files.writeString(allowed.resolve("x.jar"), "not a jar");
        HttpError e = stage(notAJar.toUri().toString(), StagingSources.parse(allowed.toString()));
        assertTrue(e.getMessage().contains("not the pinned"), "the file was not read: " + e.getMessage());
    }

    @Test
    void aRedirectIsRefusedByName() throws Exception {
        HttpServer server = HttpServer.create(new InetSocketAddress(InetAddress.getLoopbackAddress(), 0), 0);
        server.createContext("/x.jar", x -> {
            x.getResponseHeaders().add("Location", "/elsewhere.jar");
            x.sendResponseHeaders(302, -1);
            x.close();
        });
        server.createContext("/elsewhere.jar", x -> {
            byte[] b = "some other file".getBytes(StandardCharsets.UTF_8);
            x.sendResponseHeaders(200, b.length);
            try (OutputStream out = x.getResponseBody()) {
                out.write(b);
            }
        });
        server.start();
        try {
            String pin = "0".repeat(64);
            // checkUrl would refuse http: fetch is called directly to test the client's redirect rule
            URI u = URI.create("http://127.0.0.1:" + server.getAddress().getPort() + "/x.jar");
            HttpError e = assertThrows(HttpError.class, () -> Artifacts.fetch(u, pin, dir.resolve("staging"),
                    StagingSources.parse(null)));
            assertEquals(400, e.status);
            assertTrue(e.getMessage().contains("redirect refused") && e.getMessage().contains("/elsewhere.jar"),
                    e.getMessage());
            assertFalse(e.getMessage().contains("SHA-256"), "reported as a hash mismatch: " + e.getMessage());
        } finally {
            server.stop(0);
        }
        assertEquals(0, ArtifactsTest.stagedFiles(dir));
    }
}
