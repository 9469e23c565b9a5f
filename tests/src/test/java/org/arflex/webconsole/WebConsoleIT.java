package org.arflex.webconsole;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertNotNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import com.sun.net.httpserver.HttpServer;
import java.io.IOException;
import java.net.InetSocketAddress;
import java.net.URI;
import java.net.http.HttpRequest;
import java.net.http.HttpResponse;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.security.MessageDigest;
import java.time.Duration;
import java.util.HexFormat;
import java.util.List;
import java.util.Map;
import java.util.function.UnaryOperator;
import java.util.regex.Matcher;
import java.util.regex.Pattern;
import java.util.stream.Stream;
import org.junit.jupiter.api.AfterAll;
import org.junit.jupiter.api.BeforeAll;
import org.junit.jupiter.api.MethodOrderer;
import org.junit.jupiter.api.Order;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.TestMethodOrder;
import org.openqa.selenium.By;
import org.openqa.selenium.OutputType;
import org.openqa.selenium.WebElement;
import org.openqa.selenium.chrome.ChromeDriver;
import org.openqa.selenium.chrome.ChromeDriverService;
import org.openqa.selenium.chrome.ChromeOptions;
import org.openqa.selenium.support.ui.ExpectedConditions;
import org.openqa.selenium.support.ui.WebDriverWait;

/**
 * The console in Debian's headless Chromium against the real runtime (child process): login,
 * refusals, CSRF, the contract editor, install/parameter/uninstall of the sample components
 * through the pages. Screenshots of each page go to target/screenshots/. The tests run in order
 * on one runtime, as an engineer would use it.
 */
@TestMethodOrder(MethodOrderer.OrderAnnotation.class)
class WebConsoleIT {
    private static final Duration WAIT = Duration.ofSeconds(30);
    private static RuntimeUnderTest rt;
    private static ChromeDriver browser;
    private static Path screenshots;
    private static Path profile;
    private static String runtimeId;

    @BeforeAll
    static void start() throws IOException {
        Path work = Path.of(System.getProperty("arflex.it.work", "target/it")).toAbsolutePath();
        for (String exe : List.of("/usr/bin/chromium", "/usr/bin/chromedriver")) {
            assertTrue(Files.isExecutable(Path.of(exe)), exe + " is missing: install the Debian packages chromium and"
                    + " chromium-driver (scripts/setup.sh)");
        }
        screenshots = Path.of(System.getProperty("arflex.screenshots", "target/screenshots")).toAbsolutePath();
        Files.createDirectories(screenshots);
        rt = new RuntimeUnderTest(work);
        rt.awaitUp(Duration.ofSeconds(90));
        runtimeId = jsonString(rt.get("/system/console/arflex-cell/api/cell", true).body(), "runtimeId");

        profile = Files.createTempDirectory("arflex-chrome-");
        ChromeOptions o = new ChromeOptions();
        o.setBinary("/usr/bin/chromium");
        o.addArguments("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
                "--disable-component-update", "--disable-sync", "--no-first-run", "--disable-dev-shm-usage",
                "--window-size=1400,1000", "--user-data-dir=" + profile);
        ChromeDriverService service = new ChromeDriverService.Builder()
                .usingDriverExecutable(Path.of("/usr/bin/chromedriver").toFile()).usingAnyFreePort().build();
        browser = new ChromeDriver(service, o);
    }

    @AfterAll
    static void stop() throws IOException {
        try {
            if (browser != null) {
                browser.quit();
            }
        } finally {
            if (rt != null) {
                rt.close();
            }
            if (profile != null) {
                RuntimeUnderTest.deleteTree(profile);
            }
        }
        // Nothing leaks: no child process, no shared memory or queue of this runtime.
        RuntimeUnderTest.assertNothingLeft(runtimeId);
    }

    /** Logs the browser in: the Web Console uses HTTP Basic authentication. */
    private static void login() {
        browser.executeCdpCommand("Network.enable", Map.of());
        browser.executeCdpCommand("Network.setExtraHTTPHeaders", Map.of("headers", Map.of("Authorization", rt.basicAuth())));
    }

    private static void open(String labelAndQuery) {
        browser.get(rt.base() + "/system/console/" + labelAndQuery);
    }

    private static WebElement await(By by) {
        return new WebDriverWait(browser, WAIT).until(ExpectedConditions.visibilityOfElementLocated(by));
    }

    private static void awaitText(By by, String text) {
        new WebDriverWait(browser, WAIT).until(ExpectedConditions.textToBePresentInElementLocated(by, text));
    }

    /** The component page's answer to command @what ("start: done" or why not), or null after @wait. */
    private static String commandAnswer(String what, Duration wait) {
        try {
            return new WebDriverWait(browser, wait).until(d -> {
                String t = d.findElement(By.id("arflex-component-status")).getText();
                return t.contains(what + ":") ? t : null;
            });
        } catch (org.openqa.selenium.TimeoutException e) {
            return null;
        }
    }

    private static void shot(String name) throws IOException {
        Files.write(screenshots.resolve(name + ".png"), browser.getScreenshotAs(OutputType.BYTES));
    }

    /**
     * Waits until the element's text contains {@code text}; on timeout fails naming the text it
     * last showed. Returns the text.
     */
    private static String awaitElementText(By by, String text) {
        String[] seen = {null};
        try {
            new WebDriverWait(browser, WAIT).until(d -> {
                List<WebElement> e = d.findElements(by);
                seen[0] = e.isEmpty() ? null : e.get(0).getText();
                return seen[0] != null && seen[0].contains(text);
            });
        } catch (org.openqa.selenium.TimeoutException e) {
            throw new AssertionError("waited " + WAIT.toSeconds() + " s for " + by + " to show \"" + text
                    + "\"; it shows: " + (seen[0] == null ? "(no such element)" : "\"" + seen[0] + "\""), e);
        }
        return seen[0];
    }

    private static String cell() {
        return rt.get("/system/console/arflex-cell/api/cell", true).body();
    }

    private static String instanceState(String name) {
        Matcher m = Pattern.compile("\"name\":\"" + Pattern.quote(name) + "\",\"state\":\"([A-Z]+)\"").matcher(cell());
        return m.find() ? m.group(1) : null;
    }

    private static String jsonString(String json, String key) {
        Matcher m = Pattern.compile("\"" + Pattern.quote(key) + "\":\"([^\"]*)\"").matcher(json);
        return m.find() ? m.group(1) : null;
    }

    private static Path sample(String which) {
        Path p = org.arflex.it.Components.jar("sample-" + which);
        assertTrue(Files.isRegularFile(p), "sample bundle " + which + " not built: " + p);
        return p;
    }

    @Test
    @Order(1)
    void refusedWithoutOrWithWrongCredentials() throws IOException {
        HttpResponse<String> none = rt.get("/system/console/arflex-cell", false);
        assertEquals(401, none.statusCode());
        assertTrue(none.headers().firstValue("WWW-Authenticate").orElse("").startsWith("Basic"));
        HttpResponse<String> wrong = rt.send(HttpRequest.newBuilder(URI.create(rt.base() + "/system/console/arflex-cell/api/cell"))
                .header("Authorization", "Basic " + java.util.Base64.getEncoder().encodeToString("arflex:admin".getBytes(StandardCharsets.UTF_8))), false);
        assertEquals(401, wrong.statusCode());
        HttpResponse<String> admin = rt.send(HttpRequest.newBuilder(URI.create(rt.base() + "/system/console/bundles"))
                .header("Authorization", "Basic " + java.util.Base64.getEncoder().encodeToString("admin:admin".getBytes(StandardCharsets.UTF_8))), false);
        assertEquals(401, admin.statusCode(), "the Web Console default login must not work");
        // The browser without credentials gets no page either.
        open("arflex-cell");
        assertFalse(browser.getPageSource().contains("arflex-app"));
        shot("00-refused");
    }

    @Test
    @Order(2)
    void loginAndSeeTheCell() throws IOException {
        login();
        open("arflex-cell");
        await(By.id("arflex-instances"));
        awaitText(By.id("arflex-cell-status"), "Runtime");
        assertTrue(browser.findElement(By.id("arflex-resources")).getText().contains("CPU"));
        shot("01-cell-empty");
    }

    @Test
    @Order(3)
    void forgedCrossSitePostsAreRefused() throws IOException {
        // Without a token, with a wrong token: refused with 403 before anything happens.
        HttpResponse<String> noToken = rt.send(HttpRequest.newBuilder(URI.create(rt.base()
                + "/system/console/arflex-deploy/api/uninstall?name=sample-counter"))
                .header("Origin", rt.base()).POST(HttpRequest.BodyPublishers.noBody()), true);
        assertEquals(403, noToken.statusCode());
        assertTrue(noToken.body().contains("CSRF"), noToken.body());
        HttpResponse<String> wrongToken = rt.send(HttpRequest.newBuilder(URI.create(rt.base()
                + "/system/console/arflex-deploy/api/uninstall?name=sample-counter"))
                .header("Origin", rt.base()).header("X-Arflex-Csrf", "forged").POST(HttpRequest.BodyPublishers.noBody()), true);
        assertEquals(403, wrongToken.statusCode());

        // A page on another origin submits forms at the console while the browser holds the
        // credentials: ours and the Web Console's own (stop the system bundle).
        HttpServer evil = HttpServer.create(new InetSocketAddress("127.0.0.1", 0), 0);
        String target = rt.base() + "/system/console";
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
            browser.get(evilBase + "#f1");
            new WebDriverWait(browser, WAIT).until(d -> d.getCurrentUrl().contains("/api/save"));
            assertTrue(browser.getPageSource().contains("cross-"), browser.getPageSource());
            shot("02-forged-post-refused");
            assertFalse(Files.exists(rt.home.resolve("contracts/forged.xml")));
            browser.get(evilBase + "#f2");
            new WebDriverWait(browser, WAIT).until(d -> d.getCurrentUrl().contains("/bundles/0"));
            assertTrue(browser.getPageSource().contains("403"), browser.getPageSource());
        } finally {
            evil.stop(0);
        }
        assertEquals(200, rt.get("/system/console/arflex-cell/api/cell", true).statusCode(), "the runtime still runs");
    }

    @Test
    @Order(4)
    void contractEditorShowsTheErrorAtTheFieldThenSaves() throws IOException {
        open("arflex-contract");
        await(By.id("arflex-new")).click();
        WebElement name = await(By.id("arflex-f-name"));
        name.clear();
        name.sendKeys("demo-filter");
        // Markup typed into a field stays text everywhere (XML and form), never becomes an element.
        WebElement description = browser.findElement(By.cssSelector("input[data-field='description']"));
        description.sendKeys("<img id='xss' src='x' onerror='window.arflexXss=1'>");
        browser.findElement(By.id("arflex-from-xml")).click();
        assertTrue(browser.findElements(By.id("xss")).isEmpty());
        assertEquals(null, browser.executeScript("return window.arflexXss === undefined ? null : window.arflexXss;"));
        assertTrue(browser.findElement(By.id("arflex-xml")).getAttribute("value").contains("&lt;img id='xss'"));
        await(By.id("arflex-add-port")).click();
        await(By.id("arflex-add-prop")).click();
        WebElement period = await(By.id("arflex-f-timing-period"));
        period.clear();
        period.sendKeys("fast");
        assertTrue(browser.findElement(By.id("arflex-xml")).getAttribute("value").contains("period=\"fast\""));
        await(By.id("arflex-validate")).click();
        new WebDriverWait(browser, WAIT).until(d -> d.findElement(By.id("arflex-f-timing-period")).getAttribute("class").contains("arflex-invalid"));
        WebElement err = browser.findElement(By.xpath("//input[@id='arflex-f-timing-period']/following-sibling::span[@class='arflex-field-error']"));
        assertTrue(err.getText().contains("fast"), "error shown at the period field: " + err.getText());
        shot("03-contract-error-at-field");
        // Saving an invalid contract is refused with the same problems.
        await(By.id("arflex-save")).click();
        awaitText(By.id("arflex-contract-status"), "problem");
        assertFalse(Files.exists(rt.home.resolve("contracts/demo-filter.xml")));

        period = browser.findElement(By.id("arflex-f-timing-period"));
        period.clear();
        period.sendKeys("5ms");
        browser.findElement(By.id("arflex-validate")).click();
        awaitText(By.id("arflex-contract-status"), "Valid");
        browser.findElement(By.id("arflex-save")).click();
        awaitText(By.id("arflex-contract-status"), "Saved to");
        shot("04-contract-saved");
        Path saved = rt.home.resolve("contracts/demo-filter.xml");
        assertTrue(Files.isRegularFile(saved));
        assertTrue(Files.readString(saved).contains("period=\"5ms\""));
    }

    @Test
    @Order(5)
    void installTheCounterByUploadWithThePlanShown() throws IOException {
        Path counter = sample("counter");
        open("arflex-deploy");
        await(By.id("arflex-upload-file")).sendKeys(counter.toString());
        browser.findElement(By.id("arflex-upload")).click();
        WebElement plan = await(By.id("arflex-plan-text"));
        assertFalse(plan.getText().isBlank(), "a plan is shown before confirming");
        assertEquals(sha256(counter), browser.findElement(By.id("arflex-staged-sha")).getText());
        assertEquals(null, instanceState("sample-counter"), "nothing installed before confirming");
        shot("05-deploy-plan-upload");
        browser.findElement(By.id("arflex-confirm")).click();
        awaitText(By.id("arflex-deploy-status"), "installed");
        RuntimeUnderTest.awaitCondition("sample-counter Active", WAIT, () -> "ACTIVE".equals(instanceState("sample-counter")));
    }

    @Test
    @Order(6)
    void installTheScalerFromAFileUrlWithItsPinnedHash() throws IOException {
        Path scaler = sample("scaler");
        open("arflex-deploy");
        // A wrong pin is refused and nothing is installed.
        await(By.id("arflex-url")).sendKeys(scaler.toUri().toString());
        browser.findElement(By.id("arflex-sha256")).sendKeys("0".repeat(64));
        browser.findElement(By.id("arflex-fetch")).click();
        awaitText(By.id("arflex-deploy-status"), "not the pinned");
        // http is refused.
        browser.findElement(By.id("arflex-url")).clear();
        browser.findElement(By.id("arflex-url")).sendKeys("http://127.0.0.1/x.jar");
        browser.findElement(By.id("arflex-fetch")).click();
        awaitText(By.id("arflex-deploy-status"), "only https or file");
        // The right pin gives the plan, then the install.
        browser.findElement(By.id("arflex-url")).clear();
        browser.findElement(By.id("arflex-url")).sendKeys(scaler.toUri().toString());
        browser.findElement(By.id("arflex-sha256")).clear();
        browser.findElement(By.id("arflex-sha256")).sendKeys(sha256(scaler));
        browser.findElement(By.id("arflex-fetch")).click();
        assertFalse(await(By.id("arflex-plan-text")).getText().isBlank());
        shot("06-deploy-plan-url");
        browser.findElement(By.id("arflex-confirm")).click();
        awaitText(By.id("arflex-deploy-status"), "installed");
        RuntimeUnderTest.awaitCondition("sample-scaler Active", WAIT, () -> "ACTIVE".equals(instanceState("sample-scaler")));
        open("arflex-cell");
        awaitText(By.id("arflex-instances"), "sample-scaler");
        new WebDriverWait(browser, WAIT).until(d -> d.findElements(By.cssSelector("tr[data-component='sample-scaler'] .arflex-state-active")).size() == 1);
        shot("07-cell-two-components");
    }

    @Test
    @Order(7)
    void changeAParameterAndSeeItAppliedByTheRtHalf() throws IOException {
        open("arflex-component?name=sample-scaler");
        WebElement gain = await(By.id("arflex-param-gain"));
        // Out of range: refused at the field.
        gain.clear();
        gain.sendKeys("99");
        browser.findElement(By.id("arflex-apply-gain")).click();
        new WebDriverWait(browser, WAIT).until(d -> d.findElement(By.id("arflex-param-gain")).getAttribute("class").contains("arflex-invalid"));
        gain = browser.findElement(By.id("arflex-param-gain"));
        gain.clear();
        gain.sendKeys("4.25");
        browser.findElement(By.id("arflex-apply-gain")).click();
        awaitText(By.id("arflex-component-status"), "applied by the RT half");
        awaitText(By.id("arflex-applied-gain"), "4.25");
        // The live stream shows samples (server-sent events).
        awaitText(By.id("arflex-live-count"), "samples");
        awaitText(By.id("arflex-live-count"), "gain=4.25");
        // The RT half's wake-up latency histogram (StatsDTO, via the stream) is drawn.
        awaitText(By.id("arflex-histogram-summary"), "p99.9");
        new WebDriverWait(browser, WAIT).until(d -> !d.findElements(By.cssSelector("#arflex-histogram-plot canvas")).isEmpty()
                && Long.parseLong(d.findElement(By.id("arflex-histogram")).getAttribute("data-samples")) > 0);
        String hist = rt.get("/system/console/arflex-component/api/histogram?name=sample-scaler", true).body();
        assertTrue(Pattern.compile("\"binNs\":100,\"lowerEdgesNs\":\\[\\d+").matcher(hist).find(), hist);
        shot("08-component-param-applied");
        String comp = rt.get("/system/console/arflex-component/api/component?name=sample-scaler", true).body();
        assertTrue(Pattern.compile("\"name\":\"gain\",\"type\":\"[A-Z]+\",\"value\":\"4\\.25\"").matcher(comp).find(), comp);
    }

    @Test
    @Order(8)
    void graphShowsComponentsAndLinks() throws IOException {
        open("arflex-graph");
        WebElement g = await(By.id("arflex-graph"));
        new WebDriverWait(browser, WAIT).until(d -> "2".equals(g.getAttribute("data-nodes")));
        assertEquals("1", g.getAttribute("data-edges"));
        shot("09-graph");
        // Clicking a component opens its page.
        @SuppressWarnings("unchecked")
        Map<String, Object> pos = (Map<String, Object>) browser.executeScript(
                "const cy = arguments[0].arflexGraph; const n = cy.getElementById('sample-scaler');"
                + "return {x: n.renderedPosition().x, y: n.renderedPosition().y};", g);
        int w = g.getRect().getWidth();
        int h = g.getRect().getHeight();
        new org.openqa.selenium.interactions.Actions(browser)
                .moveToElement(g, (int) (((Number) pos.get("x")).doubleValue() - w / 2.0),
                        (int) (((Number) pos.get("y")).doubleValue() - h / 2.0))
                .click().perform();
        new WebDriverWait(browser, WAIT).until(d -> d.getCurrentUrl().contains("arflex-component?name=sample-scaler"));
        await(By.id("arflex-param-gain"));
    }

    @Test
    @Order(9)
    void uninstallWithThePlanShown() throws IOException {
        open("arflex-deploy");
        await(By.id("arflex-uninstall-sample-scaler")).click();
        assertFalse(await(By.id("arflex-plan-text")).getText().isBlank());
        assertNotNull(instanceState("sample-scaler"), "still installed until confirmed");
        shot("10-uninstall-plan");
        browser.findElement(By.id("arflex-confirm")).click();
        awaitText(By.id("arflex-deploy-status"), "uninstalled");
        RuntimeUnderTest.awaitCondition("sample-scaler gone", WAIT, () -> instanceState("sample-scaler") == null);
        assertEquals("ACTIVE", instanceState("sample-counter"), "the other component is not disturbed");
        open("arflex-cell");
        awaitText(By.id("arflex-instances"), "sample-counter");
        shot("11-cell-after-uninstall");
    }

    @Test
    @Order(10)
    void theCellSaysWhyAComponentIsNotActiveAndStopStartWork() throws IOException {
        Path scaler = sample("scaler");
        open("arflex-deploy");
        await(By.id("arflex-url")).sendKeys(scaler.toUri().toString());
        browser.findElement(By.id("arflex-sha256")).sendKeys(sha256(scaler));
        browser.findElement(By.id("arflex-fetch")).click();
        await(By.id("arflex-confirm")).click();
        RuntimeUnderTest.awaitCondition("sample-scaler Active again", WAIT, () -> "ACTIVE".equals(instanceState("sample-scaler")));

        // Stop the provider: the consumer loses its input and the cell says why.
        open("arflex-component?name=sample-counter");
        await(By.id("arflex-cmd-stop")).click();
        RuntimeUnderTest.awaitCondition("sample-scaler not Active", WAIT,
                () -> !"ACTIVE".equals(instanceState("sample-scaler")));
        open("arflex-cell");
        By reason = By.cssSelector("tr[data-component='sample-scaler'] .arflex-reason");
        // The resolver's reason for an explicit binding whose provider left the cell: the input,
        // the consumer and the provider's port, as the DRCR words it.
        String expected = "input 'x' of 'sample-scaler': explicit provider 'sample-counter.count' is not installed";
        String why = awaitElementText(reason, expected);
        shot("12-cell-why-not-active");
        assertEquals(expected, why.strip(), "the cell shows the DRCR's reason for the missing provider");

        // Start it again from its page: both Active.
        // A stopped bundle's component stays in the cell as INSTALLED, and its page says so.
        open("arflex-component?name=sample-counter");
        new WebDriverWait(browser, WAIT).until(d -> d.findElement(By.id("arflex-summary")).getText().contains("INSTALLED"));
        await(By.id("arflex-cmd-start")).click();
        // the console's own answer first: "start: done", or why not (a failure names it here)
        String answered = commandAnswer("start", Duration.ofSeconds(10));
        if (answered == null) {
            // Two full runs saw a click here that never reached the runtime (nothing in its log, no
            // request in the audit log) while every other click of the run did. What the page
            // showed is kept; the page is opened again and the start clicked once more: the
            // console's start must then answer.
            shot("10-start-click-without-answer");
            System.out.println("WebConsoleIT: no answer to the start click within 10 s; the page showed '"
                    + browser.findElement(By.id("arflex-component-status")).getText() + "', summary '"
                    + browser.findElement(By.id("arflex-summary")).getText().lines().findFirst().orElse("")
                    + "'; the page is opened again");
            open("arflex-component?name=sample-counter");
            new WebDriverWait(browser, WAIT).until(d -> d.findElement(By.id("arflex-summary")).getText().contains("INSTALLED"));
            await(By.id("arflex-cmd-start")).click();
            answered = commandAnswer("start", WAIT);
        }
        assertNotNull(answered, "the console never answered the start click");
        assertTrue(answered.contains("start: done"), "the console answered the start with: " + answered);
        RuntimeUnderTest.awaitCondition("both Active", WAIT,
                () -> "ACTIVE".equals(instanceState("sample-counter")) && "ACTIVE".equals(instanceState("sample-scaler")));
    }

    private static long pid(String name) {
        Matcher m = Pattern.compile("\"name\":\"" + Pattern.quote(name) + "\",\"state\"[^{}]*?\"pid\":(\\d+)").matcher(cell());
        return m.find() ? Long.parseLong(m.group(1)) : -1;
    }

    /** Waits until {@code attr} of the element is a number >= min; returns it. */
    private static long awaitAtLeast(By by, String attr, long min) {
        long[] seen = {Long.MIN_VALUE};
        new WebDriverWait(browser, WAIT).until(d -> {
            String v = d.findElement(by).getAttribute(attr);
            if (v == null || v.isBlank()) {
                return false;
            }
            seen[0] = Long.parseLong(v);
            return seen[0] >= min;
        });
        return seen[0];
    }

    /** Waits until {@code attr} of the element differs from {@code old} (and is set); returns it. */
    private static String awaitChange(By by, String attr, String old) {
        String[] seen = {null};
        new WebDriverWait(browser, WAIT).until(d -> {
            seen[0] = d.findElement(by).getAttribute(attr);
            return seen[0] != null && !seen[0].isBlank() && !seen[0].equals(old);
        });
        return seen[0];
    }

    @Test
    @Order(11)
    void aPortValuePlotShowsChangingValues() throws IOException {
        // The counter's sine (arflex.Sample state port `count`), read by the DRCR from a read-only mapping.
        String one = rt.get("/system/console/arflex-component/api/port?name=sample-counter&port=count", true).body();
        assertTrue(one.contains("\"type\":\"arflex.Sample\"") && one.contains("\"name\":\"value\""), one);
        assertEquals(404, rt.get("/system/console/arflex-component/api/port?name=sample-counter&port=nope", true).statusCode());
        assertEquals(400, rt.get("/system/console/arflex-component/api/port?name=sample-counter&port=%3Cb%3E", true).statusCode());
        long pid = pid("sample-counter");
        open("arflex-component?name=sample-counter");
        await(By.id("arflex-port-select"));
        new WebDriverWait(browser, WAIT).until(d -> "value".equals(
                new org.openqa.selenium.support.ui.Select(d.findElement(By.id("arflex-port-field"))).getFirstSelectedOption().getAttribute("value")));
        new org.openqa.selenium.support.ui.Select(browser.findElement(By.id("arflex-port-select"))).selectByValue("count");
        browser.findElement(By.id("arflex-port-plot-btn")).click();
        By plot = By.id("arflex-port-plot");
        awaitAtLeast(plot, "data-samples", 2);
        String first = browser.findElement(plot).getAttribute("data-last");
        String second = awaitChange(plot, "data-last", first);
        String third = awaitChange(plot, "data-last", second);
        assertFalse(first.equals(third) && first.equals(second), "the value changes: " + first + ", " + second + ", " + third);
        new WebDriverWait(browser, WAIT).until(d -> !d.findElements(By.cssSelector("#arflex-port-plot canvas")).isEmpty());
        awaitText(By.id("arflex-port-last"), "count.value = ");
        // Any statistic of the stream on its own plot: the cycle counter grows.
        new WebDriverWait(browser, WAIT).until(d -> new org.openqa.selenium.support.ui.Select(
                d.findElement(By.id("arflex-stat-select"))).getOptions().size() > 5);
        new org.openqa.selenium.support.ui.Select(browser.findElement(By.id("arflex-stat-select"))).selectByValue("cycles");
        By stat = By.id("arflex-stat-plot");
        awaitAtLeast(stat, "data-samples", 1);
        long c0 = Long.parseLong(browser.findElement(stat).getAttribute("data-last"));
        new WebDriverWait(browser, WAIT).until(d -> Long.parseLong(d.findElement(stat).getAttribute("data-last")) > c0);
        browser.executeScript("arguments[0].scrollIntoView();", browser.findElement(By.id("arflex-ports-live")));
        shot("13-component-port-plot");
        assertEquals(pid, pid("sample-counter"), "watching a port does not disturb its producer");
    }

    @Test
    @Order(12)
    void theCellPresetPlotsTheErrorPortOrSaysWhyNot() throws IOException {
        open("arflex-cell");
        awaitText(By.id("arflex-tcp-error-none"), "tcp-correction");
        // The same preset pointed at another Sample port (how another cell uses it): values drawn.
        open("arflex-cell?error=sample-scaler.y");
        By plot = By.id("arflex-tcp-error-plot");
        awaitAtLeast(plot, "data-samples", 2);
        awaitChange(plot, "data-last", browser.findElement(plot).getAttribute("data-last"));
        awaitText(By.id("arflex-tcp-error-last"), "y = ");
        assertTrue(browser.findElements(By.id("arflex-tcp-toggle")).isEmpty(), "no enable parameter, no toggle");
        shot("14-cell-error-preset");
    }

    @Test
    @Order(13)
    void installTheDebugMonitorWatchAValueAndUninstallItWithTheOthersUndisturbed() throws IOException {
        long counterPid = pid("sample-counter");
        long scalerPid = pid("sample-scaler");
        assertTrue(counterPid > 0 && scalerPid > 0, cell());
        open("arflex-debug");
        await(By.id("arflex-debug-jar"));
        await(By.id("arflex-debug-none"));
        new org.openqa.selenium.support.ui.Select(await(By.id("arflex-debug-target-0"))).selectByValue("sample-counter.count");
        new org.openqa.selenium.support.ui.Select(browser.findElement(By.id("arflex-debug-target-1"))).selectByValue("sample-scaler.y");
        browser.findElement(By.id("arflex-debug-plan")).click();
        assertFalse(await(By.id("arflex-plan-text")).getText().isBlank(), "the plan is shown before confirming");
        assertEquals(null, instanceState("debug-monitor"), "nothing installed before confirming");
        shot("15-debug-plan");
        browser.findElement(By.id("arflex-debug-confirm")).click();
        RuntimeUnderTest.awaitCondition("debug-monitor Active", WAIT, () -> "ACTIVE".equals(instanceState("debug-monitor")));

        // Watch: the monitor republishes the counter's value; the page shows it change.
        By last = By.id("arflex-debug-m0-last");
        long i0 = awaitAtLeast(last, "data-index", 0);
        String v0 = browser.findElement(last).getAttribute("data-value");
        awaitAtLeast(last, "data-index", i0 + 2);
        awaitChange(last, "data-value", v0);
        awaitAtLeast(By.id("arflex-debug-m1-last"), "data-index", 0);
        awaitText(By.id("arflex-debug-m0-target"), "sample-counter.count");
        awaitText(By.id("arflex-debug-m1-target"), "sample-scaler.y");
        // A smaller window: applied by the monitor's RT half, then min/max/mean arrive.
        WebElement win = browser.findElement(By.id("arflex-debug-window"));
        win.clear();
        win.sendKeys("5");
        browser.findElement(By.id("arflex-debug-window-apply")).click();
        awaitText(By.id("arflex-debug-status"), "window applied by the RT half: 5");
        awaitAtLeast(By.id("arflex-debug-m0-mean"), "data-index", 0);
        // both read in one script: the page re-renders between two separate reads
        @SuppressWarnings("unchecked")
        List<Object> mm = (List<Object>) browser.executeScript("return [document.getElementById('arflex-debug-m0-min')"
                + ".getAttribute('data-value'), document.getElementById('arflex-debug-m0-max').getAttribute('data-value')];");
        double min = Double.parseDouble(String.valueOf(mm.get(0)));
        double max = Double.parseDouble(String.valueOf(mm.get(1)));
        assertTrue(min <= max, min + " <= " + max);
        new WebDriverWait(browser, WAIT).until(d -> Long.parseLong(d.findElement(By.id("arflex-debug-plot")).getAttribute("data-samples")) > 2);
        shot("16-debug-watching");
        assertEquals(counterPid, pid("sample-counter"), "the watched counter keeps running (same pid)");
        assertEquals(scalerPid, pid("sample-scaler"), "the watched scaler keeps running (same pid)");

        // Uninstall from the same page, after its plan.
        browser.findElement(By.id("arflex-debug-uninstall")).click();
        assertFalse(await(By.id("arflex-plan-text")).getText().isBlank());
        browser.findElement(By.id("arflex-debug-confirm")).click();
        RuntimeUnderTest.awaitCondition("debug-monitor gone", WAIT, () -> instanceState("debug-monitor") == null);
        await(By.id("arflex-debug-none"));
        shot("17-debug-uninstalled");
        assertEquals("ACTIVE", instanceState("sample-counter"));
        assertEquals("ACTIVE", instanceState("sample-scaler"));
        assertEquals(counterPid, pid("sample-counter"), "the counter was not restarted");
        assertEquals(scalerPid, pid("sample-scaler"), "the scaler was not restarted");
        String prefix = "arflex." + runtimeId + ".debug-monitor.";
        RuntimeUnderTest.awaitCondition("the monitor's segments removed", WAIT, () -> {
            try (Stream<Path> st = Files.list(Path.of("/dev/shm"))) {
                return st.noneMatch(p -> p.getFileName().toString().startsWith(prefix));
            } catch (IOException e) {
                throw new java.io.UncheckedIOException(e);
            }
        });
    }

    /** A cell bundle: from the assembly's cell/, else as built in bundles/<module>/target. */
    private static Path cellJar(String module, String artifact) {
        Path assembled = Path.of(System.getProperty("arflex.runtime.dir", "../management/runtime/target/arflex-runtime"))
                .toAbsolutePath().normalize().resolve("cell").resolve(artifact + ".jar");
        if (Files.isRegularFile(assembled)) {
            return assembled;
        }
        Path root = Path.of(System.getProperty("arflex.root", "..")).toAbsolutePath().normalize();
        Path built = root.resolve("bundles").resolve(module).resolve("target").resolve(artifact + "-0.1.0-SNAPSHOT.jar");
        assertTrue(Files.isRegularFile(built), artifact + " is neither in the runtime assembly (" + assembled
                + ") nor built (" + built + ")");
        return built;
    }

    private static String paramValue(String component, String param) {
        String body = rt.get("/system/console/arflex-component/api/component?name=" + component, true).body();
        Matcher m = Pattern.compile("\"name\":\"" + Pattern.quote(param) + "\",\"type\":\"[A-Z]+\",\"value\":\"([^\"]*)\"")
                .matcher(body);
        return m.find() ? m.group(1) : null;
    }

    @Test
    @Order(14)
    void theCellPresetTogglesTheCorrectionOfTheRealTcpCorrection() throws IOException {
        // The cell's own trajectory (role=motion, its inputs optional) and tcp-correction, from the
        // assembly's cell/; without vision no error is measured, but the preset and its toggle work.
        Path trajectory = cellJar("trajectory", "org.arflex.cell.trajectory");
        Path correction = cellJar("tcp-correction", "org.arflex.cell.tcpcorrection");
        rt.gogo("start " + trajectory.toUri());
        rt.gogo("start " + correction.toUri());
        RuntimeUnderTest.awaitCondition("tcp-correction Active", Duration.ofSeconds(60),
                () -> "ACTIVE".equals(instanceState("tcp-correction")));
        String contract = rt.get("/system/console/arflex-component/api/component?name=tcp-correction", true).body();
        // The cell's tcp-correction publishes its tool-centre error: without it the preset has
        // nothing to plot, and that is a broken cell bundle, not a pass.
        assertTrue(contract.contains("\"name\":\"error\",\"direction\":\"OUT\""),
                "tcp-correction has no output port 'error' for the preset to plot: " + contract);
        open("arflex-cell");
        WebElement toggle = await(By.id("arflex-tcp-toggle"));
        By plot = By.id("arflex-tcp-error-plot");
        String before = paramValue("tcp-correction", "enable");
        assertEquals("true", before, "correction enabled by default");
        new WebDriverWait(browser, WAIT).until(d -> "on".equals(d.findElement(plot).getAttribute("data-correction")));
        awaitText(By.id("arflex-tcp-error-last"), "correction on");
        toggle.click();
        awaitText(By.id("arflex-tcp-status"), "enable applied by the RT half: false");
        new WebDriverWait(browser, WAIT).until(d -> "off".equals(d.findElement(plot).getAttribute("data-correction")));
        assertEquals("false", paramValue("tcp-correction", "enable"));
        awaitText(By.id("arflex-tcp-error-last"), "correction off");
        shot("18-cell-tcp-preset-correction-off");
        browser.findElement(By.id("arflex-tcp-toggle")).click();
        new WebDriverWait(browser, WAIT).until(d -> "on".equals(d.findElement(plot).getAttribute("data-correction")));
        assertEquals("true", paramValue("tcp-correction", "enable"));
    }

    /**
     * Copies {@code jar} to {@code out} with every OSGI-INF/arflex/*.xml contract passed through
     * {@code edit}, which must change it (an edit that matches nothing is a broken test).
     */
    private static Path withContract(Path jar, Path out, UnaryOperator<String> edit) throws IOException {
        Files.createDirectories(out.getParent());
        return org.arflex.it.Jars.withContract(jar, out, xml -> {
            String edited = edit.apply(xml);
            assertFalse(xml.equals(edited), "the edit changed nothing in the contract of " + jar.getFileName());
            return edited;
        });
    }

    /** Where the tests write their bundle variants (inside the runtime's work directory). */
    private static Path variant(String file) {
        return rt.work.resolve("jars").resolve(file);
    }

    private static final String CRITICALITY_3 = "<criticality>3</criticality>";

    /** The scaler whose contract names an update URL and pin (placed where the schema wants it). */
    private static Path scalerWithUpdate(String file, Path target, String pin) throws IOException {
        return withContract(sample("scaler"), variant(file), xml -> xml.replace(CRITICALITY_3,
                CRITICALITY_3 + "<update url=\"" + target.toUri() + "\" sha256=\"" + pin + "\"/>"));
    }

    /** Uploads a jar on the Deploy page, checks its plan is shown, confirms and waits for the status. */
    private static void uploadAndConfirm(Path jar, String statusText) {
        open("arflex-deploy");
        await(By.id("arflex-upload-file")).sendKeys(jar.toString());
        browser.findElement(By.id("arflex-upload")).click();
        assertFalse(await(By.id("arflex-plan-text")).getText().isBlank(), "a plan is shown before confirming");
        browser.findElement(By.id("arflex-confirm")).click();
        awaitElementText(By.id("arflex-deploy-status"), statusText);
    }

    private static String componentJson(String name) {
        return rt.get("/system/console/arflex-component/api/component?name=" + name, true).body();
    }

    private static String contractVersion(String name) {
        Matcher m = Pattern.compile("\"contract\":\\{\"name\":\"" + Pattern.quote(name) + "\",\"version\":\"([^\"]+)\"")
                .matcher(componentJson(name));
        return m.find() ? m.group(1) : null;
    }

    /** A POST from the console page itself (its origin, its CSRF token): "status body". */
    private static String pagePost(String api) {
        return (String) browser.executeAsyncScript(
                "const done = arguments[arguments.length - 1]; const app = document.getElementById('arflex-app');"
                + "fetch(app.dataset.root + '/api/' + arguments[0], {method: 'POST', credentials: 'same-origin',"
                + " headers: {'Accept': 'application/json', 'X-Arflex-Csrf': app.dataset.csrf}})"
                + ".then(r => r.text().then(t => done(r.status + ' ' + t))).catch(e => done('error ' + e));", api);
    }

    @Test
    @Order(15)
    void anUpdateTheDrcrCannotPlanShowsWhyAndOffersNoConfirm() throws IOException {
        long scalerPid = pid("sample-scaler");
        assertTrue(scalerPid > 0, cell());
        // No update URL in the contract: the DRCR's reason instead of a plan, and no Confirm.
        open("arflex-deploy");
        await(By.id("arflex-update-sample-scaler")).click();
        String error = awaitElementText(By.id("arflex-plan-error"), "cannot plan the update of sample-scaler");
        assertEquals("cannot plan the update of sample-scaler: its contract has no update URL", error.strip());
        assertTrue(browser.findElements(By.id("arflex-confirm")).isEmpty(), "no Confirm for a plan the DRCR could not make");
        assertTrue(browser.findElements(By.id("arflex-plan-text")).isEmpty(), "no plan text either");
        shot("19-deploy-update-no-url");
        // The JSON endpoint: CSRF-checked like every POST; from the page, a 409 naming why.
        HttpResponse<String> forged = rt.send(HttpRequest.newBuilder(URI.create(rt.base()
                + "/system/console/arflex-deploy/api/plan-update?name=sample-scaler"))
                .header("Origin", rt.base()).POST(HttpRequest.BodyPublishers.noBody()), true);
        assertEquals(403, forged.statusCode(), forged.body());
        String r = pagePost("plan-update?name=sample-scaler");
        assertEquals("409 {\"error\":\"cannot plan the update of sample-scaler: its contract has no update URL\"}", r);
        assertTrue(pagePost("plan-update?name=nope").startsWith("404 "), "an unknown component is 404");

        // A contract that pins the wrong hash: the dry run downloads and checks it, names both hashes.
        Path v2 = withContract(sample("scaler"), variant("scaler-1.1.0.jar"),
                xml -> xml.replace("version=\"1.0.0\"", "version=\"1.1.0\""));
        String wrong = "0".repeat(64);
        uploadAndConfirm(scalerWithUpdate("scaler-wrong-pin.jar", v2, wrong), "updated");
        RuntimeUnderTest.awaitCondition("the scaler with the wrong pin Active", WAIT,
                () -> "ACTIVE".equals(instanceState("sample-scaler")) && componentJson("sample-scaler").contains(wrong));
        long pinnedPid = pid("sample-scaler");
        open("arflex-deploy");
        await(By.id("arflex-update-sample-scaler")).click();
        error = awaitElementText(By.id("arflex-plan-error"), "SHA-256");
        assertTrue(error.startsWith("cannot plan the update of sample-scaler: update not installed, the old version keeps running:")
                && error.contains(v2.toUri().toString()) && error.contains(sha256(v2)) && error.contains(wrong), error);
        assertTrue(browser.findElements(By.id("arflex-confirm")).isEmpty(), "no Confirm after a hash mismatch");
        shot("20-deploy-update-wrong-pin");
        assertEquals("1.0.0", contractVersion("sample-scaler"), "nothing installed");
        assertEquals(pinnedPid, pid("sample-scaler"), "a failed plan restarts nothing");
        assertEquals("ACTIVE", instanceState("sample-scaler"));
    }

    @Test
    @Order(16)
    void updateAComponentFromTheDeployPageAfterTheDrcrsPlan() throws IOException {
        Path v2 = withContract(sample("scaler"), variant("scaler-1.1.0.jar"),
                xml -> xml.replace("version=\"1.0.0\"", "version=\"1.1.0\""));
        String pin = sha256(v2);
        uploadAndConfirm(scalerWithUpdate("scaler-1.0.0-updatable.jar", v2, pin), "updated");
        RuntimeUnderTest.awaitCondition("the updatable scaler Active", WAIT,
                () -> "ACTIVE".equals(instanceState("sample-scaler")) && componentJson("sample-scaler").contains(pin));
        assertEquals("1.0.0", contractVersion("sample-scaler"));
        long scalerPid = pid("sample-scaler");
        long counterPid = pid("sample-counter");

        open("arflex-deploy");
        await(By.id("arflex-update-sample-scaler")).click();
        String plan = await(By.id("arflex-plan-text")).getText();
        // The DRCR's dry run: from where, hash checked, and the replacement restarts only the scaler.
        assertTrue(plan.startsWith("update of sample-scaler from " + v2.toUri() + " (sha256 verified)"), plan);
        assertTrue(plan.lines().anyMatch(l -> l.matches("\\s*RESTART\\s+sample-scaler\\s.*")), plan);
        assertTrue(plan.lines().noneMatch(l -> l.matches("\\s*(STOP|RESTART)\\s+sample-counter\\s.*")), plan);
        assertEquals(pin, browser.findElement(By.id("arflex-update-sha")).getText());
        assertTrue(browser.findElement(By.id("arflex-plan")).getText().contains("Plan: update sample-scaler 1.0.0"));
        assertEquals("1.0.0", contractVersion("sample-scaler"), "a plan installs nothing");
        assertEquals(scalerPid, pid("sample-scaler"), "a plan restarts nothing");
        shot("21-deploy-update-plan");

        browser.findElement(By.id("arflex-confirm")).click();
        String report = awaitElementText(By.id("arflex-deploy-status"), "updated to 1.1.0");
        assertEquals("sample-scaler: updated to 1.1.0 from " + v2.toUri() + " (sha256 verified)", report.strip());
        RuntimeUnderTest.awaitCondition("sample-scaler 1.1.0 Active with a new pid", WAIT,
                () -> "ACTIVE".equals(instanceState("sample-scaler")) && pid("sample-scaler") > 0
                        && pid("sample-scaler") != scalerPid && "1.1.0".equals(contractVersion("sample-scaler")));
        assertEquals(counterPid, pid("sample-counter"), "the provider is not restarted");
        assertTrue(browser.findElements(By.id("arflex-confirm")).isEmpty(), "the plan is gone once confirmed");
        open("arflex-deploy");
        awaitText(By.cssSelector("tr[data-component='sample-scaler']"), "ACTIVE");
        shot("22-deploy-updated");
    }

    private static final Pattern CYCLES = Pattern.compile("\"cycles\":(\\d+)");

    private static long cycles(String name) {
        Matcher m = CYCLES.matcher(componentJson(name));
        return m.find() ? Long.parseLong(m.group(1)) : -1;
    }

    private static Boolean awaitingReset(String name) {
        Matcher m = Pattern.compile("\"awaitingReset\":(true|false)").matcher(componentJson(name));
        return m.find() ? Boolean.valueOf(m.group(1)) : null;
    }

    /** The field values (the payload) of the newest value of an output port, as api/port decodes them. */
    private static String portFields(String name, String port) {
        String body = rt.get("/system/console/arflex-component/api/port?name=" + name + "&port=" + port, true).body();
        int at = body.indexOf("\"fields\":");
        assertTrue(at >= 0, body);
        return body.substring(at);
    }

    @Test
    @Order(17)
    void theResetButtonReleasesARestartedMovingComponent() throws IOException {
        // The counter as a component that moves hardware: after a crash the DRCR restarts it held
        // (no motion) until an operator resets it.
        Path moving = withContract(sample("counter"), variant("counter-moving.jar"),
                xml -> xml.replace("movesHardware=\"false\"", "movesHardware=\"true\"").replace("<ports>",
                        "<ports><in name=\"safety\" type=\"arflex.SafetyState\" typeVersion=\"1.0\" method=\"state\" safety=\"true\"/>"));
        uploadAndConfirm(moving, "updated");
        RuntimeUnderTest.awaitCondition("the moving counter Active", WAIT, () -> "ACTIVE".equals(instanceState("sample-counter"))
                && componentJson("sample-counter").contains("\"movesHardware\":true"));
        assertEquals(Boolean.FALSE, awaitingReset("sample-counter"), "the first start needs no reset");
        long pid = pid("sample-counter");
        ProcessHandle.of(pid).ifPresent(ProcessHandle::destroyForcibly);
        RuntimeUnderTest.awaitCondition("sample-counter restarted", WAIT, () -> {
            long now = pid("sample-counter");
            return now > 0 && now != pid && "ACTIVE".equals(instanceState("sample-counter"));
        });
        assertEquals(Boolean.TRUE, awaitingReset("sample-counter"), componentJson("sample-counter"));
        long restartedPid = pid("sample-counter");
        // Held: the RT half cycles, its output does not move.
        RuntimeUnderTest.awaitCondition("the new RT half cycling", WAIT, () -> cycles("sample-counter") > 20);
        String held = portFields("sample-counter", "count");
        long c0 = cycles("sample-counter");
        RuntimeUnderTest.awaitCondition("20 more cycles", WAIT, () -> cycles("sample-counter") > c0 + 20);
        assertEquals(held, portFields("sample-counter", "count"), "a restarted moving component holds its output");

        open("arflex-component?name=sample-counter");
        awaitElementText(By.id("arflex-summary"), "restarted: waits for an operator reset before motion");
        // The live stream comes up although the sampler thread stopped while no page watched
        // (the Deploy page has no stream): its frames go on numbering from before.
        awaitElementText(By.id("arflex-live-count"), "samples; cycles");
        shot("23-component-awaiting-reset");
        await(By.id("arflex-cmd-reset")).click();
        awaitElementText(By.id("arflex-component-status"), "reset: done");
        RuntimeUnderTest.awaitCondition("the DRCR to clear awaitingReset", WAIT,
                () -> Boolean.FALSE.equals(awaitingReset("sample-counter")));
        new WebDriverWait(browser, WAIT).until(d -> !d.findElement(By.id("arflex-summary")).getText()
                .contains("waits for an operator reset"));
        RuntimeUnderTest.awaitCondition("the output moving again after the reset", WAIT,
                () -> !held.equals(portFields("sample-counter", "count")));
        shot("24-component-reset");
        assertEquals(restartedPid, pid("sample-counter"), "the reset does not restart the process");
        assertEquals("ACTIVE", instanceState("sample-counter"));

        // The same from the cell page's one button: everything that waits, and what it did.
        ProcessHandle.of(restartedPid).ifPresent(ProcessHandle::destroyForcibly);
        RuntimeUnderTest.awaitCondition("sample-counter restarted again, awaiting a reset", WAIT, () -> {
            long now = pid("sample-counter");
            return now > 0 && now != restartedPid && Boolean.TRUE.equals(awaitingReset("sample-counter"));
        });
        open("arflex-cell");
        await(By.id("arflex-reset-cell")).click();
        // everything that waits is reset (on a loaded machine that may be more than the counter)
        new WebDriverWait(browser, WAIT).until(d -> d.findElement(By.id("arflex-reset-cell-status")).getText().lines()
                .findFirst().filter(l -> l.matches("cell: reset (.+, )?sample-counter(, .+)?")).isPresent());
        RuntimeUnderTest.awaitCondition("the DRCR to clear awaitingReset after the cell reset", WAIT,
                () -> Boolean.FALSE.equals(awaitingReset("sample-counter")));
        shot("25-cell-reset");
    }

    private static String sha256(Path p) throws IOException {
        try {
            return HexFormat.of().formatHex(MessageDigest.getInstance("SHA-256").digest(Files.readAllBytes(p)));
        } catch (java.security.NoSuchAlgorithmException e) {
            throw new IllegalStateException(e);
        }
    }
}
