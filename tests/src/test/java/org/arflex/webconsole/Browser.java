package org.arflex.webconsole;

import java.io.IOException;
import java.net.ServerSocket;
import java.net.URI;
import java.net.http.HttpClient;
import java.net.http.HttpRequest;
import java.net.http.HttpResponse;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.time.Duration;
import java.util.ArrayList;
import java.util.Base64;
import java.util.List;
import java.util.Map;
import java.util.concurrent.TimeUnit;
import java.util.function.Supplier;

/**
 * Debian's headless Chromium driven by its chromedriver through the W3C WebDriver protocol
 * (JSON over HTTP on 127.0.0.1, JDK HttpClient; no Selenium), plus the two Chromium
 * extensions the browser tests need: DevTools commands ({@code goog/cdp/execute}) and the
 * browser console log ({@code se/log}). One fresh profile in a temporary folder, which
 * {@link #close()} deletes after it has ended chromedriver and every process of that profile.
 */
final class Browser implements AutoCloseable {
    static final Path CHROMIUM = Path.of("/usr/bin/chromium");
    static final Path CHROMEDRIVER = Path.of("/usr/bin/chromedriver");
    /** The W3C web element identifier key. */
    private static final String ELEMENT = "element-6066-11e4-a52e-4f735466cecf";
    private static final Duration START = Duration.ofSeconds(30);

    private final HttpClient http = HttpClient.newBuilder().connectTimeout(Duration.ofSeconds(5)).build();
    private final Path profile;
    private final Process driver;
    private final String driverBase;
    private String session;

    /** Fails (never skips) when the browser or its driver is not installed. */
    static void requireInstalled() {
        for (Path exe : List.of(CHROMIUM, CHROMEDRIVER)) {
            if (!Files.isExecutable(exe)) {
                throw new AssertionError(exe + " is missing: the browser tests need the Debian packages chromium and"
                        + " chromium-driver (scripts/setup.sh installs them; ./arflex test runs it)");
            }
        }
    }

    private Browser(Path driverLog) throws IOException {
        requireInstalled();
        this.profile = Files.createTempDirectory("arflex-browser-");
        int port;
        try (ServerSocket s = new ServerSocket(0)) {
            port = s.getLocalPort();
        }
        this.driverBase = "http://127.0.0.1:" + port;
        Files.createDirectories(driverLog.getParent());
        this.driver = new ProcessBuilder(CHROMEDRIVER.toString(), "--port=" + port,
                "--log-path=" + driverLog).redirectErrorStream(true).redirectOutput(ProcessBuilder.Redirect.DISCARD)
                .start();
    }

    /** Starts chromedriver on a free loopback port and opens a session with a fresh profile. */
    static Browser start(Path driverLog) throws IOException {
        Browser b = new Browser(driverLog);
        try {
            b.openSession();
            return b;
        } catch (RuntimeException | Error e) {
            b.close();
            throw e;
        }
    }

    private void openSession() {
        RuntimeUnderTest.awaitCondition("chromedriver at " + driverBase + " ready", START, () -> {
            if (!driver.isAlive()) {
                throw new IllegalStateException("chromedriver exited with " + driver.exitValue());
            }
            try {
                HttpResponse<String> r = http.send(HttpRequest.newBuilder(URI.create(driverBase + "/status"))
                        .timeout(Duration.ofSeconds(5)).GET().build(), HttpResponse.BodyHandlers.ofString());
                return r.statusCode() == 200 && r.body().contains("\"ready\":true");
            } catch (IOException e) {
                return false;
            } catch (InterruptedException e) {
                Thread.currentThread().interrupt();
                return false;
            }
        });
        Map<String, Object> chrome = Map.of("binary", CHROMIUM.toString(), "args", List.of("--headless=new",
                "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--no-first-run", "--disable-sync",
                "--disable-background-networking", "--disable-component-update", "--disable-extensions",
                "--window-size=1400,1000", "--user-data-dir=" + profile));
        Map<String, Object> caps = Map.of("capabilities", Map.of("alwaysMatch", Map.of("browserName", "chrome",
                "goog:chromeOptions", chrome, "goog:loggingPrefs", Map.of("browser", "ALL"),
                "unhandledPromptBehavior", "dismiss")));
        @SuppressWarnings("unchecked")
        Map<String, Object> v = (Map<String, Object>) call("POST", driverBase + "/session", caps);
        this.session = driverBase + "/session/" + v.get("sessionId");
    }

    private Object call(String method, String url, Object body) {
        HttpRequest.Builder b = HttpRequest.newBuilder(URI.create(url)).timeout(Duration.ofSeconds(90));
        if (body != null) {
            b.header("Content-Type", "application/json; charset=utf-8")
                    .method(method, HttpRequest.BodyPublishers.ofString(Json.write(body), StandardCharsets.UTF_8));
        } else {
            b.method(method, HttpRequest.BodyPublishers.noBody());
        }
        HttpResponse<String> r;
        try {
            r = http.send(b.build(), HttpResponse.BodyHandlers.ofString());
        } catch (IOException e) {
            throw new IllegalStateException("WebDriver " + method + " " + url + ": " + e, e);
        } catch (InterruptedException e) {
            Thread.currentThread().interrupt();
            throw new IllegalStateException("interrupted: WebDriver " + method + " " + url);
        }
        Object value = Json.object(r.body()).get("value");
        if (r.statusCode() != 200) {
            Map<?, ?> err = value instanceof Map<?, ?> m ? m : Map.of();
            throw new IllegalStateException("WebDriver " + method + " " + url.substring(driverBase.length()) + ": "
                    + err.get("error") + ": " + err.get("message"));
        }
        return value;
    }

    private Object session(String method, String path, Object body) {
        if (session == null) {
            throw new IllegalStateException("no WebDriver session");
        }
        return call(method, session + path, body);
    }

    /** Navigates and waits for the page to load (the WebDriver page load strategy "normal"). */
    void open(String url) {
        session("POST", "/url", Map.of("url", url));
    }

    String url() {
        return (String) session("GET", "/url", null);
    }

    String source() {
        return (String) session("GET", "/source", null);
    }

    /** Runs a script in the page (not subject to the page's CSP) and returns its value. */
    Object js(String script, Object... args) {
        return session("POST", "/execute/sync", Map.of("script", script, "args", List.of(args)));
    }

    /** The elements matching a CSS selector (their WebDriver references). */
    List<String> findAll(String css) {
        List<String> out = new ArrayList<>();
        for (Object o : (List<?>) session("POST", "/elements", Map.of("using", "css selector", "value", css))) {
            out.add((String) ((Map<?, ?>) o).get(ELEMENT));
        }
        return out;
    }

    /** An element as a script argument. */
    static Map<String, Object> ref(String element) {
        return Map.of(ELEMENT, element);
    }

    void click(String element) {
        session("POST", "/element/" + element + "/click", Map.of());
    }

    String text(String element) {
        return (String) session("GET", "/element/" + element + "/text", null);
    }

    /** A Chrome DevTools command. */
    Object cdp(String command, Map<String, Object> params) {
        return session("POST", "/goog/cdp/execute", Map.of("cmd", command, "params", params));
    }

    /** The browser console's entries since the last call (level, message). */
    List<Map<String, Object>> consoleLog() {
        List<Map<String, Object>> out = new ArrayList<>();
        for (Object o : (List<?>) session("POST", "/se/log", Map.of("type", "browser"))) {
            @SuppressWarnings("unchecked")
            Map<String, Object> m = (Map<String, Object>) o;
            out.add(m);
        }
        return out;
    }

    void screenshot(Path file) throws IOException {
        Files.createDirectories(file.getParent());
        Files.write(file, Base64.getDecoder().decode((String) session("GET", "/screenshot", null)));
    }

    /**
     * Polls {@code probe} until it returns a non-null value and returns that; on timeout fails
     * naming {@code what} and what {@code state} says then.
     */
    <T> T await(String what, Duration timeout, Supplier<T> probe, Supplier<String> state) {
        long deadline = System.nanoTime() + timeout.toNanos();
        while (true) {
            T v = probe.get();
            if (v != null) {
                return v;
            }
            if (System.nanoTime() > deadline) {
                throw new AssertionError("waited " + timeout.toSeconds() + " s for " + what + "; " + state.get());
            }
            try {
                Thread.sleep(100);
            } catch (InterruptedException e) {
                Thread.currentThread().interrupt();
                throw new AssertionError("interrupted waiting for " + what);
            }
        }
    }

    /**
     * Ends the session, chromedriver and every process started for this profile (Chromium's
     * helpers included, whoever their parent is by then), then deletes the profile. Fails if a
     * process outlives its kill.
     */
    @Override
    public void close() throws IOException {
        List<ProcessHandle> tree = new ArrayList<>(driver.descendants().toList());
        try {
            if (session != null) {
                call("DELETE", session, null);
            }
        } catch (RuntimeException e) {
            // the browser is gone already: the processes are ended below all the same
        }
        session = null;
        driver.destroy();
        try {
            if (!driver.waitFor(10, TimeUnit.SECONDS)) {
                driver.destroyForcibly().waitFor(10, TimeUnit.SECONDS);
            }
        } catch (InterruptedException e) {
            Thread.currentThread().interrupt();
        }
        String mark = profile.toString();
        ProcessHandle.allProcesses().filter(p -> p.info().commandLine().map(c -> c.contains(mark)).orElse(false))
                .forEach(tree::add);
        tree.forEach(ProcessHandle::destroy);
        long deadline = System.nanoTime() + TimeUnit.SECONDS.toNanos(10);
        while (tree.stream().anyMatch(ProcessHandle::isAlive) && System.nanoTime() < deadline) {
            try {
                Thread.sleep(100);
            } catch (InterruptedException e) {
                Thread.currentThread().interrupt();
                break;
            }
        }
        tree.stream().filter(ProcessHandle::isAlive).forEach(ProcessHandle::destroyForcibly);
        RuntimeUnderTest.awaitCondition("the browser's processes to end", Duration.ofSeconds(10),
                () -> tree.stream().noneMatch(ProcessHandle::isAlive));
        RuntimeUnderTest.deleteTree(profile);
    }
}
