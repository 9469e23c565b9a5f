package org.arflex.webconsole;

import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.nio.file.Files;
import java.nio.file.Path;
import java.time.Duration;
import java.util.ArrayList;
import java.util.List;
import java.util.concurrent.CompletableFuture;
import java.util.concurrent.CompletionException;
import java.util.regex.Matcher;
import java.util.regex.Pattern;
import org.junit.jupiter.api.extension.AfterAllCallback;
import org.junit.jupiter.api.extension.BeforeAllCallback;
import org.junit.jupiter.api.extension.ExtensionContext;
import org.openqa.selenium.chrome.ChromeDriver;
import org.openqa.selenium.chrome.ChromeDriverService;
import org.openqa.selenium.chrome.ChromeOptions;

/**
 * One console test class's runtime (child process, {@link RuntimeUnderTest}) in
 * {@code <arflex.it.work>/<name>}, optionally with sample components started or installed, and
 * optionally one headless Chromium driven by Selenium, started once the console answers (while the components start).
 * Registered on a static field ({@code @RegisterExtension}): started before the class's first
 * test, stopped after its last, then nothing of the runtime may be left (processes, shared
 * memory, queues). Its queries read the cell as the console's JSON API answers.
 */
final class ConsoleFixture implements BeforeAllCallback, AfterAllCallback {
    /** How long a component started for the class may take to get where it is asked to be. */
    private static final Duration SETUP = Duration.ofSeconds(60);
    private final String name;
    private final boolean withBrowser;
    private boolean loggedIn;
    private final List<String> started = new ArrayList<>();
    private final List<String> installed = new ArrayList<>();
    private final ConsolePages pages = new ConsolePages(this);
    private RuntimeUnderTest rt;
    private String runtimeId;
    private ChromeDriver driver;
    private Path profile;
    private Path screenshots;
    private double up;

    private ConsoleFixture(String name, boolean withBrowser) {
        this.name = name;
        this.withBrowser = withBrowser;
    }

    /** A runtime alone (tests that talk HTTP, or start their own {@link Browser}). */
    static ConsoleFixture runtime(String name) {
        return new ConsoleFixture(name, false);
    }

    /** A runtime and a Chromium that holds no login yet. */
    static ConsoleFixture withBrowser(String name) {
        return new ConsoleFixture(name, true);
    }

    /** The browser holds the console's login from the start. */
    ConsoleFixture loggedIn() {
        this.loggedIn = true;
        return this;
    }

    /** Components (bundle names as {@code org.arflex.it.Components} knows them) started, in order, each awaited ACTIVE. */
    ConsoleFixture started(String... components) {
        started.addAll(List.of(components));
        return this;
    }

    /** Components whose bundles are installed and not started, each awaited INSTALLED (after the started ones). */
    ConsoleFixture installed(String... components) {
        installed.addAll(List.of(components));
        return this;
    }

    @Override
    public void beforeAll(ExtensionContext context) throws Exception {
        long t0 = System.nanoTime();
        Path work = Path.of(System.getProperty("arflex.it.work", "target/it")).toAbsolutePath().resolve(name);
        CompletableFuture<ChromeDriver> chrome = null;
        if (withBrowser) {
            Browser.requireInstalled();
            screenshots = Path.of(System.getProperty("arflex.screenshots", "target/screenshots")).toAbsolutePath();
            Files.createDirectories(screenshots);
            profile = Files.createTempDirectory("arflex-chrome-");
        }
        Throwable failed = null;
        try {
            rt = new RuntimeUnderTest(work);
            rt.awaitUp(Duration.ofSeconds(90));
            up = seconds(t0);
            if (withBrowser) {
                // Started once the console answers, not beside the runtime's start: chromedriver
                // and Chromium take free ports of their own, and one of them could take the port
                // the runtime was given before its Jetty binds it (a runtime whose console never
                // answered was seen once with the two started side by side).
                chrome = CompletableFuture.supplyAsync(this::startChrome);
            }
            runtimeId = jsonString(cell(), "runtimeId");
            for (String c : started) {
                Path jar = org.arflex.it.Components.jar(c);
                assertTrue(Files.isRegularFile(jar), c + " not built: " + jar);
                rt.gogo("start " + jar.toUri());
                RuntimeUnderTest.awaitCondition(c + " ACTIVE", SETUP, () -> "ACTIVE".equals(state(c)));
            }
            for (String c : installed) {
                Path jar = org.arflex.it.Components.jar(c);
                assertTrue(Files.isRegularFile(jar), c + " not built: " + jar);
                rt.gogo("install " + jar.toUri());
                RuntimeUnderTest.awaitCondition(c + " INSTALLED (bundle installed, not started)", SETUP,
                        () -> "INSTALLED".equals(state(c)));
            }
        } catch (Exception | Error e) {
            failed = e;
            throw e;
        } finally {
            if (chrome != null) {
                try {
                    driver = chrome.join();
                } catch (CompletionException e) {
                    if (failed == null) {
                        throw e.getCause() instanceof RuntimeException r ? r : e;
                    }
                    failed.addSuppressed(e.getCause());
                }
            }
        }
        if (loggedIn) {
            pages.login();
        }
        // what a class of its own costs (D67): the runtime up, then with its components and browser
        System.out.printf("ConsoleFixture %s: runtime up in %.1f s, ready in %.1f s%n", name, up, seconds(t0));
    }

    private static double seconds(long since) {
        return (System.nanoTime() - since) / 1e9;
    }

    private ChromeDriver startChrome() {
        ChromeOptions o = new ChromeOptions();
        o.setBinary(Browser.CHROMIUM.toString());
        o.addArguments("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
                "--disable-component-update", "--disable-sync", "--no-first-run", "--disable-dev-shm-usage",
                "--window-size=1400,1000", "--user-data-dir=" + profile);
        ChromeDriverService service = new ChromeDriverService.Builder()
                .usingDriverExecutable(Browser.CHROMEDRIVER.toFile()).usingAnyFreePort().build();
        return new ChromeDriver(service, o);
    }

    @Override
    public void afterAll(ExtensionContext context) throws Exception {
        long t0 = System.nanoTime();
        try {
            if (driver != null) {
                driver.quit();
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
        System.out.printf("ConsoleFixture %s: stopped and checked in %.1f s%n", name, seconds(t0));
    }

    RuntimeUnderTest rt() {
        return rt;
    }

    String runtimeId() {
        return runtimeId;
    }

    /** The Selenium driver of the class's Chromium (fixtures made {@link #withBrowser}). */
    ChromeDriver driver() {
        if (driver == null) {
            throw new IllegalStateException("no browser in the fixture " + name);
        }
        return driver;
    }

    /** The page helpers on this fixture's browser. */
    ConsolePages pages() {
        return pages;
    }

    Path screenshots() {
        return screenshots;
    }

    /** Where the tests write their bundle variants (inside the runtime's work directory, trusted by the code gate). */
    Path variant(String file) {
        return rt.work.resolve("jars").resolve(file);
    }

    // ---- the cell, as the console's JSON API shows it

    String cell() {
        return rt.get("/system/console/arflex-cell/api/cell", true).body();
    }

    /** The instance's state (ACTIVE, INSTALLED, ...), null when the cell has no such instance. */
    String state(String name) {
        Matcher m = Pattern.compile("\"name\":\"" + Pattern.quote(name) + "\",\"state\":\"([A-Z]+)\"").matcher(cell());
        return m.find() ? m.group(1) : null;
    }

    long pid(String name) {
        Matcher m = Pattern.compile("\"name\":\"" + Pattern.quote(name) + "\",\"state\"[^{}]*?\"pid\":(\\d+)").matcher(cell());
        return m.find() ? Long.parseLong(m.group(1)) : -1;
    }

    String componentJson(String name) {
        return rt.get("/system/console/arflex-component/api/component?name=" + name, true).body();
    }

    String paramValue(String component, String param) {
        Matcher m = Pattern.compile("\"name\":\"" + Pattern.quote(param) + "\",\"type\":\"[A-Z]+\",\"value\":\"([^\"]*)\"")
                .matcher(componentJson(component));
        return m.find() ? m.group(1) : null;
    }

    String contractVersion(String name) {
        Matcher m = Pattern.compile("\"contract\":\\{\"name\":\"" + Pattern.quote(name) + "\",\"version\":\"([^\"]+)\"")
                .matcher(componentJson(name));
        return m.find() ? m.group(1) : null;
    }

    private static final Pattern CYCLES = Pattern.compile("\"cycles\":(\\d+)");

    long cycles(String name) {
        Matcher m = CYCLES.matcher(componentJson(name));
        return m.find() ? Long.parseLong(m.group(1)) : -1;
    }

    Boolean awaitingReset(String name) {
        Matcher m = Pattern.compile("\"awaitingReset\":(true|false)").matcher(componentJson(name));
        return m.find() ? Boolean.valueOf(m.group(1)) : null;
    }

    /** The field values (the payload) of the newest value of an output port, as api/port decodes them. */
    String portFields(String name, String port) {
        String body = rt.get("/system/console/arflex-component/api/port?name=" + name + "&port=" + port, true).body();
        int at = body.indexOf("\"fields\":");
        assertTrue(at >= 0, body);
        return body.substring(at);
    }

    static String jsonString(String json, String key) {
        Matcher m = Pattern.compile("\"" + Pattern.quote(key) + "\":\"([^\"]*)\"").matcher(json);
        return m.find() ? m.group(1) : null;
    }
}
