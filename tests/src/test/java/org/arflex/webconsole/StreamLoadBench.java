package org.arflex.webconsole;

import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.net.CookieManager;
import java.net.URI;
import java.net.http.HttpClient;
import java.net.http.HttpRequest;
import java.net.http.HttpResponse;
import java.nio.file.Files;
import java.nio.file.Path;
import java.time.Duration;
import java.util.ArrayList;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Locale;
import java.util.Map;
import java.util.regex.Matcher;
import java.util.regex.Pattern;
import org.junit.jupiter.api.Test;
import org.openqa.selenium.By;
import org.openqa.selenium.chrome.ChromeDriver;
import org.openqa.selenium.chrome.ChromeDriverService;
import org.openqa.selenium.chrome.ChromeOptions;
import org.openqa.selenium.support.ui.ExpectedConditions;
import org.openqa.selenium.support.ui.WebDriverWait;

/**
 * Benchmark, not a test (run on purpose: {@code mvn -o -Darflex.native.skip=true -pl web-console
 * verify -Dit.test=StreamLoadBench}): the RT statistics of the two sample components over a
 * fixed window, once with no browser and once while three headless browsers show the component
 * page with its live plots (server-sent events at 10 Hz: statistics, and the value of the
 * component's output port read from its segment). Prints a table and writes
 * target/bench/stream-load.json. The components are restarted (bundle stop/start) before each
 * window so each window's statistics start from zero.
 */
class StreamLoadBench {
    private static final Duration WINDOW = Duration.ofSeconds(Long.getLong("arflex.bench.seconds", 30));
    private static final String[] COMPONENTS = {"sample-counter", "sample-scaler"};

    private RuntimeUnderTest rt;
    private final HttpClient http = HttpClient.newBuilder().cookieHandler(new CookieManager()).build();
    private String token;

    @Test
    void rtLatencyWithAndWithoutThreeStreamingBrowsers() throws Exception {
        Path work = Path.of(System.getProperty("arflex.it.work", "target/it")).toAbsolutePath().resolve("bench");
        List<ChromeDriver> browsers = new ArrayList<>();
        List<Path> profiles = new ArrayList<>();
        Map<String, Object> result = new LinkedHashMap<>();
        try {
            rt = new RuntimeUnderTest(work);
            rt.awaitUp(Duration.ofSeconds(90));
            HttpResponse<String> page = send(HttpRequest.newBuilder(uri("/system/console/arflex-deploy")).GET());
            Matcher m = Pattern.compile("data-csrf='([^']+)'").matcher(page.body());
            assertTrue(m.find(), "page carries the CSRF token");
            token = m.group(1);
            install(org.arflex.it.Components.jar("sample-counter").toAbsolutePath().normalize());
            install(org.arflex.it.Components.jar("sample-scaler").toAbsolutePath().normalize());

            result.put("idle", window());

            for (int i = 0; i < 3; i++) {
                Path profile = Files.createTempDirectory("arflex-bench-chrome-");
                profiles.add(profile);
                ChromeOptions o = new ChromeOptions();
                o.setBinary("/usr/bin/chromium");
                o.addArguments("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
                        "--disable-component-update", "--disable-sync", "--no-first-run", "--disable-dev-shm-usage",
                        "--user-data-dir=" + profile);
                ChromeDriver b = new ChromeDriver(new ChromeDriverService.Builder()
                        .usingDriverExecutable(Path.of("/usr/bin/chromedriver").toFile()).usingAnyFreePort().build(), o);
                browsers.add(b);
                b.executeCdpCommand("Network.enable", Map.of());
                b.executeCdpCommand("Network.setExtraHTTPHeaders", Map.of("headers", Map.of("Authorization", rt.basicAuth())));
                b.get(rt.base() + "/system/console/arflex-component?name=" + COMPONENTS[i % 2]);
                new WebDriverWait(b, Duration.ofSeconds(30)).until(
                        ExpectedConditions.textToBePresentInElementLocated(By.id("arflex-live-count"), "samples"));
                // Also plot the component's output port value (the same stream then carries it).
                new WebDriverWait(b, Duration.ofSeconds(30)).until(d -> !new org.openqa.selenium.support.ui.Select(
                        d.findElement(By.id("arflex-port-field"))).getOptions().isEmpty());
                b.findElement(By.id("arflex-port-plot-btn")).click();
                new WebDriverWait(b, Duration.ofSeconds(30)).until(d -> {
                    String n = d.findElement(By.id("arflex-port-plot")).getAttribute("data-samples");
                    return n != null && Long.parseLong(n) > 0;
                });
            }
            result.put("threeBrowsers", window());
        } finally {
            for (ChromeDriver b : browsers) {
                b.quit();
            }
            if (rt != null) {
                rt.close();
            }
            for (Path p : profiles) {
                RuntimeUnderTest.deleteTree(p);
            }
        }
        print(result);
        Path out = Path.of("target/bench/stream-load.json").toAbsolutePath();
        Files.createDirectories(out.getParent());
        Files.writeString(out, json(result) + "\n");
        System.out.println("written " + out);
    }

    /** Restarts both components, waits the window, returns their statistics. */
    private Map<String, Object> window() throws Exception {
        for (String c : COMPONENTS) {
            post("/api/command?name=" + c + "&cmd=stop", null);
        }
        for (String c : COMPONENTS) {
            post("/api/command?name=" + c + "&cmd=start", null);
        }
        RuntimeUnderTest.awaitCondition("both Active", Duration.ofSeconds(30), () -> {
            String cell = cell();
            return cell.contains("\"name\":\"sample-counter\",\"state\":\"ACTIVE\"")
                    && cell.contains("\"name\":\"sample-scaler\",\"state\":\"ACTIVE\"");
        });
        Thread.sleep(WINDOW.toMillis()); // the measurement window itself, not a wait for a condition
        Map<String, Object> stats = new LinkedHashMap<>();
        for (String c : COMPONENTS) {
            String body = send(HttpRequest.newBuilder(uri("/system/console/arflex-component/api/component?name=" + c)).GET()).body();
            Map<String, Object> s = new LinkedHashMap<>();
            for (String k : new String[] {"cycles", "overruns", "wcetOverruns", "maxLatencyNs", "latencyP50Ns",
                "latencyP99Ns", "latencyP999Ns", "maxExecNs", "meanExecNs"}) {
                Matcher m = Pattern.compile("\"stats\":\\{[^}]*\"" + k + "\":(\\d+)").matcher(body);
                s.put(k, m.find() ? Long.parseLong(m.group(1)) : null);
            }
            stats.put(c, s);
        }
        return stats;
    }

    private String cell() {
        return send(HttpRequest.newBuilder(uri("/system/console/arflex-cell/api/cell")).GET()).body();
    }

    private void install(Path jar) throws IOException {
        String staged = post("/api/stage-upload?file=" + jar.getFileName(), jar);
        Matcher m = Pattern.compile("\"id\":\"([0-9a-f]+)\"").matcher(staged);
        assertTrue(m.find(), staged);
        post("/api/install?id=" + m.group(1), null);
    }

    private String post(String api, Path body) throws IOException {
        HttpRequest.Builder b = HttpRequest.newBuilder(uri("/system/console/arflex-deploy" + api))
                .header("Origin", rt.base()).header("X-Arflex-Csrf", token)
                .POST(body == null ? HttpRequest.BodyPublishers.noBody() : HttpRequest.BodyPublishers.ofFile(body));
        HttpResponse<String> r = send(b);
        assertTrue(r.statusCode() == 200, api + ": " + r.statusCode() + " " + r.body());
        return r.body();
    }

    private URI uri(String path) {
        return URI.create(rt.base() + path);
    }

    private HttpResponse<String> send(HttpRequest.Builder b) {
        try {
            return http.send(b.header("Authorization", rt.basicAuth()).timeout(Duration.ofSeconds(20)).build(),
                    HttpResponse.BodyHandlers.ofString());
        } catch (IOException e) {
            throw new IllegalStateException(e);
        } catch (InterruptedException e) {
            Thread.currentThread().interrupt();
            throw new IllegalStateException(e);
        }
    }

    @SuppressWarnings("unchecked")
    private static void print(Map<String, Object> result) {
        System.out.printf(Locale.ROOT, "%-14s %-15s %9s %9s %9s %10s %10s %10s %14s %12s %12s%n", "run", "component",
                "cycles", "overruns", "wcet-over", "lat-p50-us", "lat-p99-us", "p99.9-us", "max-latency-us", "max-exec-us",
                "mean-exec-us");
        result.forEach((run, comps) -> ((Map<String, Object>) comps).forEach((c, v) -> {
            Map<String, Object> s = (Map<String, Object>) v;
            System.out.printf(Locale.ROOT, "%-14s %-15s %9s %9s %9s %10.1f %10.1f %10.1f %14.1f %12.1f %12.1f%n", run, c,
                    s.get("cycles"), s.get("overruns"), s.get("wcetOverruns"), us(s.get("latencyP50Ns")),
                    us(s.get("latencyP99Ns")), us(s.get("latencyP999Ns")), us(s.get("maxLatencyNs")),
                    us(s.get("maxExecNs")), us(s.get("meanExecNs")));
        }));
    }

    private static double us(Object ns) {
        return ns instanceof Long l ? l / 1000.0 : Double.NaN;
    }

    @SuppressWarnings("unchecked")
    private static String json(Object o) {
        if (o instanceof Map<?, ?> m) {
            StringBuilder sb = new StringBuilder("{");
            ((Map<String, Object>) m).forEach((k, v) -> sb.append(sb.length() > 1 ? "," : "").append('"').append(k)
                    .append("\":").append(json(v)));
            return sb.append('}').toString();
        }
        return String.valueOf(o);
    }
}
