package org.arflex.webconsole;

import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.net.CookieManager;
import java.net.URI;
import java.net.http.HttpClient;
import java.net.http.HttpRequest;
import java.net.http.HttpResponse;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.time.Duration;
import java.util.ArrayList;
import java.util.List;
import java.util.Locale;
import java.util.function.BooleanSupplier;
import java.util.regex.Matcher;
import java.util.regex.Pattern;
import java.util.stream.Stream;
import org.junit.jupiter.api.Test;

/**
 * The console's part of the attack benchmark ({@code ./arflex bench attack}, issue 16 finding
 * 1): every state-changing endpoint (Felix's bundles and configuration pages, ours: command,
 * parameter, contract save, uninstall), reached through every spelling of the console's path
 * (encoded, double-encoded, case, dot-segments, path parameters, doubled and encoded slashes),
 * with the browser's credentials but a foreign Origin, a foreign Referer only, neither, a
 * {@code null} Origin, and (our pages only) our own origin without the token. An attempt <em>succeeded</em> when
 * its effect is seen (bundle stopped, component stopped, parameter or file written) or the
 * server accepted it (status below 400). Controls: the same requests from the console's origin
 * with its token have their effect. Then the hostile contracts of the tests through the
 * validate API: succeeded when it answers 500 or the console stops answering. Last, issue 30's
 * doors ({@link LoginAndAuditDoors}): a cross-site flood of the audit log, a password-guessing
 * burst. Prints one line
 * per door (variants summed) and {@code attack-part: console S/N attempts succeeded}; writes
 * target/bench/attack-console.json. Not a test: run by the script only.
 */
class ConsoleAttackBench {

    private static final String[] PATHS = {"/system/console", "/%73ystem/console", "/%2573ystem/console",
        "/SYSTEM/console", "/system/./console", "/system/x/../console", "/system/console;x=1", "//system/console",
        "/system%2fconsole", "/system%2Fconsole", "/system/%63onsole", "/system/console/.", "/%2e/system/console"};
    private static final String EVIL = "http://evil.example";

    record Door(String name, String method, String path, String body, BooleanSupplier effect, Runnable restore) {
    }

    private RuntimeUnderTest rt;
    private final HttpClient http = HttpClient.newBuilder().connectTimeout(Duration.ofSeconds(5))
            .cookieHandler(new CookieManager()).build();
    private String token;
    private final List<String[]> lines = new ArrayList<>();
    private int succeeded;
    private int total;

    @Test
    void attack() throws Exception {
        Path work = Path.of(System.getProperty("arflex.it.work", "target/it")).resolve("console-attack").toAbsolutePath();
        Path counter = org.arflex.it.Components.jar("sample-counter");
        try (RuntimeUnderTest r = new RuntimeUnderTest(work)) {
            rt = r;
            rt.awaitUp(Duration.ofSeconds(90));
            rt.gogo("install " + counter.toUri());
            RuntimeUnderTest.awaitCondition("the counter installed", Duration.ofSeconds(30),
                    () -> Pattern.compile("Bundle ID: \\d+").matcher(rt.tail()).find());
            Matcher installed = Pattern.compile("Bundle ID: (\\d+)").matcher(rt.tail());
            installed.find();
            rt.gogo("start " + installed.group(1));
            RuntimeUnderTest.awaitCondition("sample-counter ACTIVE", Duration.ofSeconds(30),
                    () -> component().contains("\"state\":\"ACTIVE\""));
            long bundle = bundleId("org.arflex.samples.counter");
            token = sessionToken();

            List<Door> doors = List.of(
                    new Door("felix bundles/<id> action=stop", "POST", "/bundles/" + bundle, "action=stop",
                            () -> !bundleState(bundle).contains("Active"), () -> felix(bundle, "start")),
                    new Door("felix configMgr/<pid> apply", "POST", "/configMgr/org.arflex.attack.forged",
                            "apply=true&action=ajaxConfigManager&propertylist=x&x=1",
                            () -> get("/system/console/configMgr/org.arflex.attack.forged.json").contains("\"x\""),
                            () -> felixPost("/configMgr/org.arflex.attack.forged", "apply=true&delete=true")),
                    new Door("arflex command stop", "POST", "/arflex-cell/api/command?name=sample-counter&cmd=stop", "",
                            () -> !component().contains("\"state\":\"ACTIVE\""), () -> legit("/arflex-cell/api/command?name=sample-counter&cmd=start")),
                    new Door("arflex param amplitude=777", "POST",
                            "/arflex-cell/api/param?name=sample-counter&param=amplitude&value=777", "",
                            () -> component().contains("777"), () -> legit(
                                    "/arflex-cell/api/param?name=sample-counter&param=amplitude&value=1")),
                    new Door("arflex contract save", "POST", "/arflex-contract/api/save?name=forged",
                            Files.readString(Path.of(System.getProperty("arflex.root", "..")).resolve(
                                    "bundles/sample-counter/src/main/resources/OSGI-INF/arflex/sample-counter.xml")),
                            () -> Files.exists(rt.home.resolve("contracts/forged.xml")),
                            () -> deleteQuietly(rt.home.resolve("contracts/forged.xml"))));
            // Controls: from the console itself, with its token, every door has its effect.
            for (Door d : doors) {
                send(d, "/system/console", "Origin", rt.base(), true);
                boolean seen = waitFor(d.effect());
                if (!seen) {
                    throw new AssertionError("control failed: '" + d.name() + "' from the console itself had no effect\n"
                            + rt.tail());
                }
                d.restore().run();
                RuntimeUnderTest.awaitCondition("restored after " + d.name(), Duration.ofSeconds(30),
                        () -> !d.effect().getAsBoolean());
                System.out.println("attack: control: " + d.name() + " from the console's origin with its token: effect seen");
            }
            String[][] headers = {{"Origin", EVIL}, {"Referer", EVIL + "/page"}, {null, null}, {"Origin", "null"},
                {"Origin", rt.base()}};
            String[] headerNames = {"foreign Origin", "foreign Referer", "no Origin/Referer", "Origin null",
                "own Origin, no token"};
            for (Door d : doors) {
                for (int h = 0; h < headers.length; h++) {
                    if (d.name().startsWith("felix") && headers[h][1] != null && headers[h][1].equals(rt.base())) {
                        continue; // Felix's own pages carry no token: from the console's origin they are the console
                    }
                    int n = 0;
                    int ok = 0;
                    StringBuilder which = new StringBuilder();
                    java.util.Map<Integer, Integer> statuses = new java.util.TreeMap<>();
                    for (String p : PATHS) {
                        HttpResponse<String> resp = send(d, p, headers[h][0], headers[h][1], false);
                        int status = resp == null ? -1 : resp.statusCode();
                        statuses.merge(status, 1, Integer::sum);
                        boolean effect = d.effect().getAsBoolean();
                        n++;
                        if (effect || (status >= 200 && status < 400)) {
                            ok++;
                            which.append(p).append(" -> ").append(status).append(effect ? " (effect) " : " ");
                            if (effect) {
                                d.restore().run();
                                RuntimeUnderTest.awaitCondition("restored after " + d.name(), Duration.ofSeconds(30),
                                        () -> !d.effect().getAsBoolean());
                            }
                        }
                    }
                    record(d.name() + ", " + headerNames[h], n, ok, ok == 0 ? "answered (status=count) " + statuses
                            : "ACCEPTED: " + which);
                }
            }
            everyOtherEndpoint();
            corpus();
            ChangeSetFileDoor.Result f = ChangeSetFileDoor.tryOn(rt, counter.toUri().toString());
            record(ChangeSetFileDoor.DOOR + (f.controlSeen() ? "" : " (CONTROL NOT SEEN)"), f.tries(), f.succeeded(), f.detail());
            new LoginAndAuditDoors(rt, this::record).run(); // issue 30: audit flood, password guessing (last: back-off)
            assertTrue(rt.get("/system/console/arflex-cell/api/cell", true).statusCode() == 200, "the runtime still runs");
        }
        StringBuilder json = new StringBuilder("{\"part\":\"console\",\"attempts\":[");
        for (int k = 0; k < lines.size(); k++) {
            String[] l = lines.get(k);
            json.append(k == 0 ? "" : ",").append(String.format(Locale.ROOT,
                    "{\"door\":\"%s\",\"tries\":%s,\"succeeded\":%s,\"detail\":\"%s\"}", esc(l[0]), l[1], l[2], esc(l[3])));
        }
        json.append(String.format(Locale.ROOT, "],\"succeeded\":%d,\"total\":%d}%n", succeeded, total));
        Path out = Path.of(System.getProperty("arflex.bench.out.dir", "target/bench"), "attack-console.json");
        Files.createDirectories(out.toAbsolutePath().getParent());
        Files.writeString(out, json);
        System.out.println("JSON: " + out.toAbsolutePath());
        System.out.printf(Locale.ROOT, "attack-part: console %d/%d attempts succeeded%n", succeeded, total);
    }

    /**
     * Every other state-changing endpoint (ours and Felix's), from a foreign origin through every
     * path spelling: judged by the answer (the cross-site check answers 403 before the endpoint
     * runs; anything below 400 counts as a success for the attacker).
     */
    private void everyOtherEndpoint() {
        String[][] endpoints = {
            {"arflex stage-url", "/arflex-deploy/api/stage-url?url=file:/etc/passwd&sha256=" + "0".repeat(64)},
            {"arflex stage-upload", "/arflex-deploy/api/stage-upload"},
            {"arflex install (staged)", "/arflex-deploy/api/install?id=1"},
            {"arflex discard (staged)", "/arflex-deploy/api/discard?id=1"},
            {"arflex uninstall", "/arflex-deploy/api/uninstall?name=sample-counter"},
            {"arflex update", "/arflex-deploy/api/update?name=sample-counter&sha256=" + "0".repeat(64)},
            {"arflex plan-update", "/arflex-deploy/api/plan-update?name=sample-counter"},
            {"arflex validate", "/arflex-contract/api/validate"},
            {"arflex debug-stage", "/arflex-debug/api/debug-stage?targets=sample-counter.count"},
            {"arflex command reset", "/arflex-cell/api/command?name=sample-counter&cmd=reset"},
            {"felix bundles install", "/bundles"},
            {"felix vmstat shutdown", "/vmstat"},
            {"felix components (DS) disable", "/components/0"},
            {"felix configMgr create", "/configMgr/%5BTemporary%20PID%20replaced%20by%20real%20PID%20upon%20save%5D"}};
        String[] bodies = {"", "", "", "", "", "", "", "<component/>", "", "", "action=install", "shutdown_type=Stop",
            "action=disable", "apply=true&factoryPid=org.arflex.x&propertylist=a&a=1"};
        String[][] origins = {{"Origin", EVIL}, {"Referer", EVIL + "/page"}, {null, null}, {"Origin", "null"}};
        for (int e = 0; e < endpoints.length; e++) {
            int n = 0;
            int ok = 0;
            java.util.Map<Integer, Integer> statuses = new java.util.TreeMap<>();
            StringBuilder which = new StringBuilder();
            Door d = new Door(endpoints[e][0], "POST", endpoints[e][1], bodies[e], () -> false, () -> { });
            for (String[] o : origins) {
                for (String p : PATHS) {
                    HttpResponse<String> resp = send(d, p, o[0], o[1], false);
                    int status = resp == null ? -1 : resp.statusCode();
                    statuses.merge(status, 1, Integer::sum);
                    n++;
                    if (status >= 200 && status < 400) {
                        ok++;
                        which.append(p).append(' ').append(o[0]).append(" -> ").append(status).append("; ");
                    }
                }
            }
            record(d.name() + ", foreign/missing/null origins", n, ok, ok == 0 ? "answered (status=count) " + statuses
                    : "ACCEPTED: " + which);
        }
        if (rt.get("/system/console/arflex-cell/api/cell", true).statusCode() != 200) {
            throw new AssertionError("the runtime stopped answering after the endpoint attempts\n" + rt.tail());
        }
    }

    /** The hostile contracts of the contract tests, through the validate API. */
    private void corpus() throws IOException {
        Path root = Path.of(System.getProperty("arflex.root", "..")).toAbsolutePath().normalize();
        List<Path> files = new ArrayList<>();
        for (String dir : new String[] {"contracts/src/test/resources"}) {
            Path d = root.resolve(dir);
            if (Files.isDirectory(d)) {
                try (Stream<Path> s = Files.walk(d)) {
                    s.filter(p -> p.toString().endsWith(".xml") || p.getParent().getFileName().toString().contains("fuzz"))
                            .filter(Files::isRegularFile).filter(p -> sizeOf(p) < 2_000_000).forEach(files::add);
                }
            }
        }
        // and the ones the parser must survive whatever the corpus holds
        List<byte[]> extra = List.of(("<?xml version='1.0'?><!DOCTYPE c [<!ENTITY x SYSTEM 'file:///etc/passwd'>]>"
                + "<component name='a'>&x;</component>").getBytes(StandardCharsets.UTF_8),
                ("<component name='" + "a".repeat(200_000) + "'/>").getBytes(StandardCharsets.UTF_8),
                ("<c>" + "x".repeat(150_000) + "</c>").getBytes(StandardCharsets.UTF_8),
                "<a>".repeat(20_000).getBytes(StandardCharsets.UTF_8));
        int n = 0;
        int bad = 0;
        StringBuilder which = new StringBuilder();
        List<byte[]> bodies = new ArrayList<>(extra);
        for (Path f : files) {
            bodies.add(Files.readAllBytes(f));
        }
        for (byte[] b : bodies) {
            HttpResponse<String> r = legitPost("/arflex-contract/api/validate", b);
            n++;
            boolean leaked = r != null && r.body().contains("root:");
            if (r == null || r.statusCode() >= 500 || leaked) {
                bad++;
                which.append(r == null ? "no answer" : r.statusCode() + (leaked ? " leaked a file" : "")).append("; ");
            }
        }
        record("hostile contracts through validate (" + files.size() + " corpus files + " + extra.size() + ")", n, bad,
                bad == 0 ? "every one answered with problems, none 500" : which.toString());
    }

    private void record(String door, int tries, int ok, String detail) {
        total += tries;
        succeeded += ok;
        lines.add(new String[] {door, Integer.toString(tries), Integer.toString(ok), detail});
        System.out.printf(Locale.ROOT, "attack: %-58s %s  %d tries, %s%n", door, ok == 0 ? "refused" : "SUCCEEDED",
                tries, detail.length() > 200 ? detail.substring(0, 200) + "..." : detail);
    }

    private HttpResponse<String> send(Door d, String prefix, String header, String value, boolean withToken) {
        HttpRequest.Builder b = HttpRequest.newBuilder(URI.create(rt.base() + prefix + d.path()))
                .header("Authorization", rt.basicAuth()).header("Content-Type",
                        d.body().startsWith("<") ? "application/xml" : "application/x-www-form-urlencoded")
                .method(d.method(), HttpRequest.BodyPublishers.ofString(d.body()));
        if (header != null) {
            b.header(header, value);
        }
        if (withToken) {
            b.header("X-Arflex-Csrf", token);
        }
        return send(b);
    }

    private HttpResponse<String> send(HttpRequest.Builder b) {
        try {
            return http.send(b.timeout(Duration.ofSeconds(10)).build(), HttpResponse.BodyHandlers.ofString());
        } catch (IOException | IllegalArgumentException e) {
            return null;
        } catch (InterruptedException e) {
            Thread.currentThread().interrupt();
            throw new IllegalStateException(e);
        }
    }

    private HttpResponse<String> legitPost(String path, byte[] body) {
        return send(HttpRequest.newBuilder(URI.create(rt.base() + "/system/console" + path))
                .header("Authorization", rt.basicAuth()).header("Origin", rt.base()).header("X-Arflex-Csrf", token)
                .header("Content-Type", "application/xml").POST(HttpRequest.BodyPublishers.ofByteArray(body)));
    }

    private void legit(String path) {
        HttpResponse<String> r = legitPost(path, new byte[0]);
        if (r == null || r.statusCode() >= 400) {
            throw new AssertionError("restoring through " + path + ": " + (r == null ? "no answer" : r.statusCode() + " " + r.body()));
        }
    }

    private void felix(long bundle, String action) {
        felixPost("/bundles/" + bundle, "action=" + action);
    }

    /** A form post to one of Felix's pages from the console's own origin (as its pages do). */
    private void felixPost(String path, String form) {
        HttpResponse<String> r = send(HttpRequest.newBuilder(URI.create(rt.base() + "/system/console" + path))
                .header("Authorization", rt.basicAuth()).header("Origin", rt.base())
                .header("Content-Type", "application/x-www-form-urlencoded")
                .POST(HttpRequest.BodyPublishers.ofString(form)));
        if (r == null || r.statusCode() >= 400) {
            throw new AssertionError(path + " " + form + ": " + (r == null ? "no answer" : r.statusCode()));
        }
    }

    private String get(String path) {
        HttpResponse<String> r = send(HttpRequest.newBuilder(URI.create(rt.base() + path))
                .header("Authorization", rt.basicAuth()).GET());
        return r == null || r.statusCode() != 200 ? "" : r.body();
    }

    private String component() {
        return get("/system/console/arflex-cell/api/component?name=sample-counter");
    }

    private String bundleState(long id) {
        return get("/system/console/bundles/" + id + ".json");
    }

    private long bundleId(String bsn) {
        String all = get("/system/console/bundles.json");
        Matcher m = Pattern.compile("\\{\"id\":(\\d+),[^{}]*\"symbolicName\":\"" + Pattern.quote(bsn) + "\"").matcher(all);
        if (!m.find()) {
            throw new AssertionError("no bundle " + bsn + " in " + all.substring(0, Math.min(400, all.length())));
        }
        return Long.parseLong(m.group(1));
    }

    /** The token of a console session (the page carries it; the cookie names the session). */
    private String sessionToken() {
        String page = get("/system/console/arflex-cell");
        Matcher m = Pattern.compile("data-csrf='([^']+)'").matcher(page);
        if (!m.find()) {
            throw new AssertionError("no CSRF token on the cell page");
        }
        return m.group(1);
    }

    private static boolean waitFor(BooleanSupplier c) {
        try {
            RuntimeUnderTest.awaitCondition("the effect", Duration.ofSeconds(15), c);
            return true;
        } catch (AssertionError e) {
            return false;
        }
    }

    private static long sizeOf(Path p) {
        try {
            return Files.size(p);
        } catch (IOException e) {
            return Long.MAX_VALUE;
        }
    }

    private static void deleteQuietly(Path p) {
        try {
            Files.deleteIfExists(p);
        } catch (IOException e) {
            throw new IllegalStateException(e);
        }
    }

    private static String esc(String s) {
        return s.replace("\\", "\\\\").replace("\"", "\\\"").replaceAll("[\\x00-\\x1f]", " ");
    }
}
