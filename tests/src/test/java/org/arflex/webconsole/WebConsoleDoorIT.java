package org.arflex.webconsole;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertTrue;

import com.sun.net.httpserver.HttpServer;
import java.io.IOException;
import java.net.InetSocketAddress;
import java.net.URI;
import java.net.http.HttpRequest;
import java.net.http.HttpResponse;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import org.junit.jupiter.api.MethodOrderer;
import org.junit.jupiter.api.Order;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.TestMethodOrder;
import org.junit.jupiter.api.extension.RegisterExtension;
import org.openqa.selenium.By;

/**
 * The console's door in Debian's headless Chromium against the real runtime (child process):
 * no page without the console's login (none, a wrong one, the Web Console's default), the
 * login opens the cell, and forged posts (no or a wrong CSRF token; forms on another origin
 * submitted while the browser holds the login) are refused. Screenshots to target/screenshots/.
 */
@TestMethodOrder(MethodOrderer.OrderAnnotation.class)
class WebConsoleDoorIT {
    @RegisterExtension
    static final ConsoleFixture FX = ConsoleFixture.withBrowser("webconsole-door");
    private static final ConsolePages PAGES = FX.pages();

    @Test
    @Order(1)
    void refusedWithoutOrWithWrongCredentials() throws IOException {
        HttpResponse<String> none = FX.rt().get("/system/console/arflex-cell", false);
        assertEquals(401, none.statusCode());
        assertTrue(none.headers().firstValue("WWW-Authenticate").orElse("").startsWith("Basic"));
        HttpResponse<String> wrong = FX.rt().send(HttpRequest.newBuilder(URI.create(FX.rt().base() + "/system/console/arflex-cell/api/cell"))
                .header("Authorization", "Basic " + java.util.Base64.getEncoder().encodeToString("arflex:admin".getBytes(StandardCharsets.UTF_8))), false);
        assertEquals(401, wrong.statusCode());
        HttpResponse<String> admin = FX.rt().send(HttpRequest.newBuilder(URI.create(FX.rt().base() + "/system/console/bundles"))
                .header("Authorization", "Basic " + java.util.Base64.getEncoder().encodeToString("admin:admin".getBytes(StandardCharsets.UTF_8))), false);
        assertEquals(401, admin.statusCode(), "the Web Console default login must not work");
        // The PAGES.driver() without credentials gets no page either.
        PAGES.open("arflex-cell");
        assertFalse(PAGES.driver().getPageSource().contains("arflex-app"));
        PAGES.shot("00-refused");
    }

    @Test
    @Order(2)
    void loginAndSeeTheCell() throws IOException {
        PAGES.login();
        PAGES.open("arflex-cell");
        PAGES.await(By.id("arflex-instances"));
        PAGES.awaitText(By.id("arflex-cell-status"), "Runtime");
        assertTrue(PAGES.driver().findElement(By.id("arflex-resources")).getText().contains("CPU"));
        PAGES.shot("01-cell-empty");
    }

    @Test
    @Order(3)
    void forgedCrossSitePostsAreRefused() throws IOException {
        // Without a token, with a wrong token: refused with 403 before anything happens.
        HttpResponse<String> noToken = FX.rt().send(HttpRequest.newBuilder(URI.create(FX.rt().base()
                + "/system/console/arflex-deploy/api/uninstall?name=sample-counter"))
                .header("Origin", FX.rt().base()).POST(HttpRequest.BodyPublishers.noBody()), true);
        assertEquals(403, noToken.statusCode());
        assertTrue(noToken.body().contains("CSRF"), noToken.body());
        HttpResponse<String> wrongToken = FX.rt().send(HttpRequest.newBuilder(URI.create(FX.rt().base()
                + "/system/console/arflex-deploy/api/uninstall?name=sample-counter"))
                .header("Origin", FX.rt().base()).header("X-Arflex-Csrf", "forged").POST(HttpRequest.BodyPublishers.noBody()), true);
        assertEquals(403, wrongToken.statusCode());

        // A page on another origin submits forms at the console while the PAGES.driver() holds the
        // credentials: ours and the Web Console's own (stop the system bundle).
        HttpServer evil = HttpServer.create(new InetSocketAddress("127.0.0.1", 0), 0);
        String target = FX.rt().base() + "/system/console";
        String page = "<html><body><form id='f1' method='POST' action='" + target
                + "/arflex-contract/api/save?name=forged'><input name='_csrf' value='guess'></form>"
                + "<form id='f2' method='POST' action='" + target + "/bundles/0'>"
                + "<input name='action' value='stop'></form>"
                + "<p id='which'></p><script>var w=location.hash.substring(1);document.getElementById(w).submit();</script></body></html>";
        evil.createContext("/evil", ex -> {
            byte[] b = page.getBytes(StandardCharsets.UTF_8);
            ex.getResponseHeaders().add("Content-Type", "text/html");
            ex.sendResponseHeaders(200, b.length);
            ex.getResponseBody().write(b);
            ex.close();
        });
        evil.start();
        try {
            String evilBase = "http://localhost:" + evil.getAddress().getPort() + "/evil";
            PAGES.driver().get(evilBase + "#f1");
            PAGES.waiting().until(d -> d.getCurrentUrl().contains("/api/save"));
            assertTrue(PAGES.driver().getPageSource().contains("cross-"), PAGES.driver().getPageSource());
            PAGES.shot("02-forged-post-refused");
            assertFalse(Files.exists(FX.rt().home.resolve("contracts/forged.xml")));
            PAGES.driver().get(evilBase + "#f2");
            PAGES.waiting().until(d -> d.getCurrentUrl().contains("/bundles/0"));
            assertTrue(PAGES.driver().getPageSource().contains("403"), PAGES.driver().getPageSource());
        } finally {
            evil.stop(0);
        }
        assertEquals(200, FX.rt().get("/system/console/arflex-cell/api/cell", true).statusCode(), "the runtime still runs");
    }
}
