package org.arflex.webconsole;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.net.URI;
import java.net.http.HttpRequest;
import java.nio.file.Files;
import java.nio.file.Path;
import java.nio.file.attribute.PosixFilePermissions;
import java.time.Duration;
import org.junit.jupiter.api.Test;

/**
 * Issue 16, remote use: with TLS on (ARFLEX_CONSOLE_TLS=true here on loopback; any
 * ARFLEX_CONSOLE_HOST beyond loopback turns it on), scripts/run-cell.sh generates the console's
 * key in the home (0600), serves the console over HTTPS only and turns plain HTTP off.
 */
class ConsoleTlsIT {

    @Test
    void theConsoleIsServedOverHttpsOnlyWithAGeneratedKey() throws Exception {
        Path work = Path.of(System.getProperty("arflex.it.work", "target/it")).resolve("console-tls").toAbsolutePath();
        try (RuntimeUnderTest rt = new RuntimeUnderTest(work, true)) {
            rt.awaitUp(Duration.ofSeconds(90));
            assertTrue(rt.base().startsWith("https://"), rt.base());
            assertEquals(200, rt.get("/system/console/arflex-cell/api/cell", true).statusCode());
            assertEquals(401, rt.get("/system/console/arflex-cell/api/cell", false).statusCode(), "still needs the login");
            // plain HTTP is off: nothing answers on the configured port
            assertNull(rt.send(HttpRequest.newBuilder(URI.create(rt.plainBase() + "/system/console/arflex-cell/api/cell"))
                    .GET(), true), "plain HTTP must not answer");
            for (String f : new String[] {"console-tls.p12", "console-tls.pass"}) {
                assertEquals("rw-------", PosixFilePermissions.toString(Files.getPosixFilePermissions(rt.home.resolve(f))), f);
            }
            assertTrue(Files.readString(rt.log).contains("web console at https://127.0.0.1:" + rt.tlsPort), rt.tail());
        }
    }
}
