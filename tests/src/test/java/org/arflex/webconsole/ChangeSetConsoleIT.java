package org.arflex.webconsole;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertNotNull;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.net.CookieManager;
import java.net.URI;
import java.net.URLEncoder;
import java.net.http.HttpClient;
import java.net.http.HttpRequest;
import java.net.http.HttpResponse;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.time.Duration;
import java.util.ArrayList;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import java.util.regex.Matcher;
import java.util.regex.Pattern;
import org.junit.jupiter.api.AfterAll;
import org.junit.jupiter.api.BeforeAll;
import org.junit.jupiter.api.MethodOrderer;
import org.junit.jupiter.api.Order;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.TestMethodOrder;

/**
 * The Change sets page's endpoints (D46) on the real runtime, through HTTP as its page uses
 * them: sample-counter running, sample-scaler's bundle installed and not started. In order:
 * the dry run of {@code install sample-scaler} shows START sample-scaler and changes nothing;
 * forged applies of that very plan (foreign Origin or Referer, none, {@code Origin: null},
 * missing or forged token, each through percent-encoded spellings of the apply URL) are
 * refused and apply nothing; a plan made stale by stopping the counter is refused on apply;
 * then the set is applied, its outcome is "committed" with the plan shown, the scaler runs
 * beside the unchanged counter; a second set uninstalls the scaler and sets the counter's
 * amplitude; the history lists both newest first; the audit log has the applies, their
 * outcomes and the refusals. Then the page in Chromium; last, an update of the scaler with a
 * shadow run and a rollback window applied from the page, whose live progress (D53) the page
 * shows going through the shadow run (its cycles) and the window to the outcome, and whose
 * progress endpoint answers no one without the console's credentials, however its path is spelt;
 * then a set of two updates (the counter with a window, the scaler with a shadow run and a
 * window), whose rows the page shows each with its own counters, kept with the outcome (D60).
 */
@TestMethodOrder(MethodOrderer.OrderAnnotation.class)
class ChangeSetConsoleIT {
    private static final Duration WAIT = Duration.ofSeconds(60);
    private static final String PAGE = "/system/console/arflex-changesets";
    private static final String EVIL = "http://evil.example";
    /** The apply URL as an attacker may spell it: every one names the console (ConsolePath). */
    private static final String[] PREFIXES = {"/system/console", "/%73ystem/console", "/%2573ystem/console",
        "/SYSTEM/console", "/system/./console", "/system/x/../console", "/system/console;x=1", "//system/console",
        "/system%2fconsole", "/system/%63onsole", "/%2e/system/console"};
    private static RuntimeUnderTest rt;
    private static String runtimeId;
    private static final HttpClient HTTP = HttpClient.newBuilder().connectTimeout(Duration.ofSeconds(5))
            .cookieHandler(new CookieManager()).build();
    private static String token;

    @BeforeAll
    static void start() throws IOException {
        Path work = Path.of(System.getProperty("arflex.it.work", "target/it")).resolve("changeset-console").toAbsolutePath();
        rt = new RuntimeUnderTest(work);
        rt.awaitUp(Duration.ofSeconds(90));
        runtimeId = string(rt.get("/system/console/arflex-cell/api/cell", true).body(), "runtimeId");
        Path counter = org.arflex.it.Components.jar("sample-counter");
        Path scaler = org.arflex.it.Components.jar("sample-scaler");
        assertTrue(Files.isRegularFile(counter) && Files.isRegularFile(scaler), "sample bundles not built");
        rt.gogo("start " + counter.toUri());
        RuntimeUnderTest.awaitCondition("sample-counter ACTIVE", WAIT, () -> "ACTIVE".equals(state("sample-counter")));
        rt.gogo("install " + scaler.toUri());
        RuntimeUnderTest.awaitCondition("sample-scaler INSTALLED (bundle installed, not started)", WAIT,
                () -> "INSTALLED".equals(state("sample-scaler")));
        String page = send(HttpRequest.newBuilder(URI.create(rt.base() + PAGE)).GET(), true).body();
        Matcher m = Pattern.compile("data-csrf='([^']+)'").matcher(page);
        assertTrue(m.find(), "no CSRF token on the Change sets page: " + page);
        token = m.group(1);
        assertTrue(page.contains("data-page='changesets'"), page);
    }

    @AfterAll
    static void stop() throws IOException {
        if (rt != null) {
            rt.close();
        }
        RuntimeUnderTest.assertNothingLeft(runtimeId);
    }

    // ---- helpers

    private static HttpResponse<String> send(HttpRequest.Builder b, boolean auth) {
        if (auth) {
            b.header("Authorization", rt.basicAuth());
        }
        try {
            return HTTP.send(b.timeout(Duration.ofSeconds(30)).build(), HttpResponse.BodyHandlers.ofString());
        } catch (IOException e) {
            return null;
        } catch (InterruptedException e) {
            Thread.currentThread().interrupt();
            throw new IllegalStateException(e);
        }
    }

    private static String form(Map<String, String> fields) {
        List<String> out = new ArrayList<>();
        fields.forEach((k, v) -> out.add(URLEncoder.encode(k, StandardCharsets.UTF_8) + "="
                + URLEncoder.encode(v, StandardCharsets.UTF_8)));
        return String.join("&", out);
    }

    /** A POST of a form to {@code prefix + rest}, with the headers given (null: not sent) and the token or not. */
    private static HttpResponse<String> post(String prefix, String rest, Map<String, String> fields, String header,
                                             String value, String csrf) {
        HttpRequest.Builder b = HttpRequest.newBuilder(URI.create(rt.base() + prefix + rest))
                .header("Content-Type", "application/x-www-form-urlencoded")
                .POST(HttpRequest.BodyPublishers.ofString(form(fields)));
        if (header != null) {
            b.header(header, value);
        }
        if (csrf != null) {
            b.header("X-Arflex-Csrf", csrf);
        }
        return send(b, true);
    }

    /** The page's own POST: same origin, the session's token. */
    private static Map<String, Object> legit(String endpoint, Map<String, String> fields, int expect) {
        HttpResponse<String> r = post("/system/console", "/arflex-changesets/api/" + endpoint, fields, "Origin", rt.base(),
                token);
        assertNotNull(r, "no answer to " + endpoint);
        assertEquals(expect, r.statusCode(), endpoint + ": " + r.body());
        return Json.object(r.body());
    }

    private static Map<String, Object> status() {
        HttpResponse<String> r = send(HttpRequest.newBuilder(URI.create(rt.base() + PAGE + "/api/changesets")).GET(), true);
        assertEquals(200, r.statusCode(), r.body());
        return Json.object(r.body());
    }

    private static String cell() {
        return rt.get("/system/console/arflex-cell/api/cell", true).body();
    }

    private static String state(String name) {
        Matcher m = Pattern.compile("\"name\":\"" + Pattern.quote(name) + "\",\"state\":\"([A-Z]+)\"").matcher(cell());
        return m.find() ? m.group(1) : null;
    }

    private static long pid(String name) {
        Matcher m = Pattern.compile("\"name\":\"" + Pattern.quote(name) + "\",\"state\"[^{}]*?\"pid\":(\\d+)").matcher(cell());
        return m.find() ? Long.parseLong(m.group(1)) : -1;
    }

    private static String string(String json, String key) {
        Matcher m = Pattern.compile("\"" + Pattern.quote(key) + "\":\"([^\"]*)\"").matcher(json);
        return m.find() ? m.group(1) : null;
    }

    private static List<Map<String, Object>> history() {
        @SuppressWarnings("unchecked")
        List<Map<String, Object>> h = (List<Map<String, Object>>) status().get("history");
        return h;
    }

    @SuppressWarnings("unchecked")
    private static Map<String, Object> awaitOutcome() {
        Map<String, Object>[] seen = new Map[1];
        RuntimeUnderTest.awaitCondition("the outcome of the apply", WAIT, () -> {
            Map<String, Object> s = status();
            seen[0] = s;
            return s.get("applying") == null && s.get("last") != null;
        });
        return (Map<String, Object>) seen[0].get("last");
    }

    // ---- the tests, in order on one runtime

    private static String shownPlanId;

    @Test
    @Order(1)
    @SuppressWarnings("unchecked")
    void theDryRunShowsTheWholeSetAndChangesNothing() {
        long counterPid = pid("sample-counter");
        Map<String, Object> r = legit("changeset-plan", Map.of("actions", "# the scaler joins\ninstall sample-scaler\n"), 200);
        assertEquals(true, r.get("admitted"), String.valueOf(r));
        Map<String, Object> parts = (Map<String, Object>) r.get("parts");
        List<Map<String, Object>> steps = (List<Map<String, Object>>) parts.get("steps");
        assertTrue(steps.stream().anyMatch(s -> "START".equals(s.get("op")) && "sample-scaler".equals(s.get("component"))),
                "START sample-scaler: " + r.get("text"));
        assertFalse(steps.stream().anyMatch(s -> "sample-counter".equals(s.get("component"))
                && !"REBIND".equals(s.get("op"))), "nothing happens to the counter: " + r.get("text"));
        assertFalse(((List<?>) parts.get("cpus")).isEmpty(), "the admission per CPU: " + r.get("text"));
        assertTrue(((List<String>) parts.get("wiring")).contains("sample-scaler.x <- sample-counter.count"),
                String.valueOf(parts.get("wiring")));
        shownPlanId = (String) r.get("planId");
        assertTrue(shownPlanId.matches("[0-9a-f]{64}"));
        assertEquals("INSTALLED", state("sample-scaler"), "a dry run starts nothing");
        assertEquals(counterPid, pid("sample-counter"));
        // a bad line is named before the DRCR is asked
        HttpResponse<String> bad = post("/system/console", "/arflex-changesets/api/changeset-plan",
                Map.of("actions", "install sample-scaler\ninstal sample-counter"), "Origin", rt.base(), token);
        assertEquals(400, bad.statusCode());
        assertTrue(bad.body().contains("line 2 ('instal sample-counter'): unknown action 'instal'"), bad.body());
    }

    @Test
    @Order(2)
    void forgedAppliesOfThePlanShownAreRefusedAndApplyNothing() {
        Map<String, String> fields = new LinkedHashMap<>();
        fields.put("actions", "install sample-scaler");
        fields.put("plan", shownPlanId);
        String[][] how = {
            {"Origin", EVIL, token}, {"Referer", EVIL + "/page", token}, {null, null, token}, {"Origin", "null", token},
            {"Origin", rt.base(), null}, {"Origin", rt.base(), "forged-token"}, {"Sec-Fetch-Site", "cross-site", token},
        };
        String[] named = {"foreign Origin", "foreign Referer", "no Origin or Referer", "Origin null", "own Origin, no token",
            "own Origin, forged token", "Sec-Fetch-Site cross-site"};
        int tries = 0;
        List<String> accepted = new ArrayList<>();
        for (int h = 0; h < how.length; h++) {
            for (String prefix : PREFIXES) {
                HttpResponse<String> r = post(prefix, "/arflex-changesets/api/changeset-apply", fields, how[h][0], how[h][1],
                        how[h][2]);
                tries++;
                int st = r == null ? -1 : r.statusCode();
                if (st >= 200 && st < 400) {
                    accepted.add(named[h] + " " + prefix + " -> " + st);
                }
                if (prefix.equals("/system/console")) {
                    assertEquals(403, st, named[h] + ": " + (r == null ? "" : r.body()));
                }
            }
        }
        System.out.println("ChangeSetConsoleIT: " + tries + " forged applies, " + accepted.size() + " accepted");
        assertTrue(accepted.isEmpty(), "accepted: " + accepted);
        Map<String, Object> s = status();
        assertEquals(null, s.get("applying"), "nothing is being applied");
        assertEquals(null, s.get("last"));
        assertTrue(history().isEmpty(), "the DRCR applied no set: " + history());
        assertEquals("INSTALLED", state("sample-scaler"));
    }

    @Test
    @Order(3)
    void aPlanMadeStaleByAChangeOfTheCellIsRefusedOnApply() {
        HttpResponse<String> stop = post("/system/console", "/arflex-component/api/command?name=sample-counter&cmd=stop",
                Map.of(), "Origin", rt.base(), token);
        assertEquals(200, stop.statusCode(), stop.body());
        RuntimeUnderTest.awaitCondition("sample-counter stopped", WAIT, () -> !"ACTIVE".equals(state("sample-counter")));
        HttpResponse<String> r = post("/system/console", "/arflex-changesets/api/changeset-apply",
                Map.of("actions", "install sample-scaler", "plan", shownPlanId), "Origin", rt.base(), token);
        assertEquals(409, r.statusCode(), r.body());
        assertTrue(r.body().contains("the cell changed since the plan was shown"), r.body());
        assertEquals("INSTALLED", state("sample-scaler"), "nothing applied");
        assertTrue(history().isEmpty());
        HttpResponse<String> start = post("/system/console", "/arflex-component/api/command?name=sample-counter&cmd=start",
                Map.of(), "Origin", rt.base(), token);
        assertEquals(200, start.statusCode(), start.body());
        RuntimeUnderTest.awaitCondition("sample-counter ACTIVE again", WAIT, () -> "ACTIVE".equals(state("sample-counter")));
    }

    @Test
    @Order(4)
    void theSetIsAppliedAsPlannedAndItsOutcomeAndHistoryShown() {
        long counterPid = pid("sample-counter");
        Map<String, Object> plan = legit("changeset-plan", Map.of("actions", "install sample-scaler"), 200);
        assertEquals(true, plan.get("admitted"));
        Map<String, Object> r = legit("changeset-apply", Map.of("actions", "install sample-scaler",
                "plan", (String) plan.get("planId")), 200);
        assertEquals("applying", r.get("state"));
        Map<String, Object> last = awaitOutcome();
        assertEquals("committed", last.get("outcome"), String.valueOf(last));
        assertEquals(true, last.get("planAsShown"), String.valueOf(last));
        assertEquals(true, last.get("applied"));
        RuntimeUnderTest.awaitCondition("sample-scaler ACTIVE", WAIT, () -> "ACTIVE".equals(state("sample-scaler")));
        assertEquals(counterPid, pid("sample-counter"), "the counter was not restarted");
        List<Map<String, Object>> h = history();
        assertEquals(1, h.size(), String.valueOf(h));
        assertEquals(List.of("install sample-scaler"), h.get(0).get("actions"));
        assertEquals("committed", h.get(0).get("outcome"));
        assertTrue(((Number) h.get(0).get("finishedMillis")).longValue() > 0);
        System.out.println("ChangeSetConsoleIT: install sample-scaler: prepared in " + last.get("prepareMs")
                + " ms, switch turn " + last.get("switchUs") + " µs");
    }

    @Test
    @Order(5)
    @SuppressWarnings("unchecked")
    void aSecondSetUninstallsAndSetsAndTheHistoryListsBothNewestFirst() {
        long counterPid = pid("sample-counter");
        String set = "uninstall sample-scaler\nset sample-counter amplitude 3.5";
        Map<String, Object> plan = legit("changeset-plan", Map.of("actions", set), 200);
        assertEquals(true, plan.get("admitted"), String.valueOf(plan));
        List<Map<String, Object>> steps = (List<Map<String, Object>>) ((Map<String, Object>) plan.get("parts")).get("steps");
        assertTrue(steps.stream().anyMatch(s -> "STOP".equals(s.get("op")) && "sample-scaler".equals(s.get("component"))),
                String.valueOf(plan.get("text")));
        legit("changeset-apply", Map.of("actions", set, "plan", (String) plan.get("planId")), 200);
        Map<String, Object> last = awaitOutcome();
        assertEquals(List.of("uninstall sample-scaler", "set sample-counter amplitude 3.5"), last.get("actions"));
        assertEquals("committed", last.get("outcome"), String.valueOf(last));
        RuntimeUnderTest.awaitCondition("sample-scaler INSTALLED again", WAIT, () -> "INSTALLED".equals(state("sample-scaler")));
        assertEquals(counterPid, pid("sample-counter"));
        String comp = rt.get("/system/console/arflex-component/api/component?name=sample-counter", true).body();
        assertTrue(Pattern.compile("\"name\":\"amplitude\",\"type\":\"[A-Z]+\",\"value\":\"3\\.5\"").matcher(comp).find(), comp);
        List<Map<String, Object>> h = history();
        assertEquals(2, h.size(), String.valueOf(h));
        assertEquals(List.of("uninstall sample-scaler", "set sample-counter amplitude 3.5"), h.get(0).get("actions"));
        assertEquals(List.of("install sample-scaler"), h.get(1).get("actions"));
    }

    @Test
    @Order(6)
    @SuppressWarnings("unchecked")
    void theAuditLogHasTheAppliesTheirOutcomesAndTheRefusals() {
        String body = rt.get("/system/console/arflex-audit/api/audit", true).body();
        List<Map<String, Object>> entries = (List<Map<String, Object>>) Json.object(body).get("entries");
        String apply = "/system/console/arflex-changesets/api/changeset-apply";
        List<Map<String, Object>> outcomes = entries.stream().filter(e -> "OUTCOME".equals(e.get("method"))).toList();
        assertEquals(2, outcomes.size(), body);
        for (Map<String, Object> o : outcomes) {
            assertEquals(apply, o.get("path"));
            assertEquals("committed", ((Map<String, Object>) o.get("params")).get("outcome"));
            assertEquals("arflex", o.get("user"));
        }
        assertTrue(outcomes.stream().anyMatch(o -> "install sample-scaler".equals(
                ((Map<String, Object>) o.get("params")).get("actions"))), body);
        List<Map<String, Object>> refused = entries.stream().filter(e -> apply.equals(e.get("path"))
                && ((Number) e.get("status")).intValue() == 403).toList();
        assertFalse(refused.isEmpty(), "the refused forged applies are in the audit log: " + body);
        assertTrue(refused.stream().anyMatch(e -> shownPlanId.equals(((Map<String, Object>) e.get("params")).get("plan"))
                && "install sample-scaler".equals(((Map<String, Object>) e.get("params")).get("actions"))), body);
        assertTrue(entries.stream().anyMatch(e -> apply.equals(e.get("path")) && ((Number) e.get("status")).intValue() == 409
                && String.valueOf(e.get("reason")).startsWith("the cell changed since the plan was shown")), body);
    }

    /** Sets the page's actions as typed (the input event included) and clicks Plan. */
    private static void planInTheBrowser(Browser b, String actions) {
        b.js("const t = document.getElementById('arflex-cs-actions'); t.value = arguments[0];"
                + "t.dispatchEvent(new Event('input'));", actions);
        b.click(b.findAll("#arflex-cs-plan-btn").get(0));
    }

    /** The text of the first element matching {@code css}, read in one call (the page redraws parts every second). */
    private static String textOf(Browser b, String css) {
        return (String) b.js("const e = document.querySelector(arguments[0]); return e ? e.innerText : null;", css);
    }

    @Test
    @Order(7)
    void thePageShowsThePlanAppliesItAndShowsTheOutcomeWithMarkupKeptAsText() throws IOException {
        Browser.requireInstalled();
        Path work = Path.of(System.getProperty("arflex.it.work", "target/it")).resolve("changeset-console").toAbsolutePath();
        try (Browser b = Browser.start(work.resolve("chromedriver.log"))) {
            b.cdp("Network.enable", Map.of());
            b.cdp("Network.setExtraHTTPHeaders", Map.of("headers", Map.of("Authorization", rt.basicAuth())));
            b.open(rt.base() + PAGE);
            b.await("the page", WAIT, () -> textOf(b, "#arflex-cs-history-table"), b::url);
            // markup typed as an action stays text in the refusal, and runs nothing
            planInTheBrowser(b, "install <img id=xss src=x onerror=window.__pwned=1>");
            String error = b.await("the refusal of line 1", WAIT, () -> textOf(b, "#arflex-cs-plan-error"), b::source);
            assertTrue(error.startsWith("line 1 ('install <img id=xss"), error);
            assertTrue(b.findAll("#xss").isEmpty(), "no element made of the text");
            assertEquals(null, b.js("return window.__pwned === undefined ? null : window.__pwned;"));
            // the plan of the whole set, then applied from the page
            planInTheBrowser(b, "install sample-scaler");
            b.await("START sample-scaler in the plan", WAIT,
                    () -> b.findAll("#arflex-cs-plan-steps tr[data-op='START'][data-component='sample-scaler']").isEmpty()
                            ? null : Boolean.TRUE, b::source);
            assertTrue(textOf(b, "#arflex-cs-admission").startsWith("Admitted (dry run: nothing changed)"));
            assertFalse(b.findAll("#arflex-cs-plan-cpus tr[data-cpu]").isEmpty(), "the admission per CPU is shown");
            b.screenshot(Path.of(System.getProperty("arflex.screenshots", "target/screenshots")).resolve("changesets-plan.png"));
            assertEquals("INSTALLED", state("sample-scaler"), "nothing happens before the apply");
            b.click(b.findAll("#arflex-cs-apply").get(0));
            String outcome = b.await("the outcome", WAIT, () -> {
                String t = textOf(b, "#arflex-cs-outcome[data-outcome]");
                return t != null && t.startsWith("Last set applied here: install sample-scaler \u2014") ? t : null;
            }, b::source);
            assertEquals(null, textOf(b, "#arflex-cs-status .arflex-msg"), "the note 'Applying the set' is gone");
            assertTrue(outcome.contains("committed"), outcome);
            RuntimeUnderTest.awaitCondition("sample-scaler ACTIVE", WAIT, () -> "ACTIVE".equals(state("sample-scaler")));
            b.await("three sets in the history", WAIT,
                    () -> b.findAll("#arflex-cs-history-table tr[data-outcome='committed']").size() == 3 ? Boolean.TRUE : null,
                    b::source);
            b.screenshot(Path.of(System.getProperty("arflex.screenshots", "target/screenshots")).resolve("changesets-outcome.png"));
        }
    }

    /**
     * D50: deployment sets refused before their change set, one for its descriptor, one by the
     * code gate, are in the DRCR's history as the page lists it: the action {@code deploy <url>},
     * refused, with the reason (the descriptor's line; the jar and both hashes); nothing applied.
     */
    @Test
    @Order(8)
    void deploymentSetsRefusedBeforeTheirChangeSetAreInTheHistoryWithTheirReason() throws IOException {
        Path dir = Files.createDirectories(Path.of(System.getProperty("arflex.it.work", "target/it"))
                .resolve("changeset-console").toAbsolutePath().resolve("sets"));
        Path bad = Files.writeString(dir.resolve("bad.xml"), "<deployment xmlns=\"urn:arflex:deployment:1\">\n"
                + "  <uninstall component=\"sample-counter\" jar=\"x.jar\"/>\n</deployment>\n");
        Path scaler = org.arflex.it.Components.jar("sample-scaler");
        String zeros = "0".repeat(64);
        Path pin = Files.writeString(dir.resolve("pin.xml"), "<deployment xmlns=\"urn:arflex:deployment:1\">\n"
                + "  <install jar=\"" + scaler.toUri() + "\" sha256=\"" + zeros + "\"/>\n</deployment>\n");
        int before = history().size();
        String scalerState = state("sample-scaler");
        rt.gogo("arflex:deploy set " + bad.toUri());
        rt.gogo("arflex:deploy set " + pin.toUri());
        RuntimeUnderTest.awaitCondition("two refused deployment sets in the history", WAIT,
                () -> history().size() == before + 2);
        List<Map<String, Object>> h = history();
        Map<String, Object> gate = h.get(0);
        Map<String, Object> syntax = h.get(1);
        assertEquals(List.of("deploy " + bad.toUri()), syntax.get("actions"));
        assertEquals("refused", syntax.get("outcome"), String.valueOf(syntax));
        assertEquals(false, syntax.get("applied"));
        assertTrue(String.valueOf(syntax.get("why")).matches("descriptor: " + Pattern.quote(bad.toUri().toString())
                + ":2:\\d+: <uninstall>: unknown attribute 'jar' \\(allowed: component\\)"), String.valueOf(syntax));
        assertEquals(List.of("deploy " + pin.toUri()), gate.get("actions"));
        assertEquals("refused", gate.get("outcome"), String.valueOf(gate));
        String why = String.valueOf(gate.get("why"));
        assertTrue(why.startsWith("jar " + scaler.toUri() + " (line 2, install): ") && why.contains("pinned " + zeros)
                && why.endsWith("; nothing installed"), why);
        assertEquals(scalerState, state("sample-scaler"), "nothing of the refused sets changed the cell");
    }

    /** A copy of the sample-scaler bundle whose contract says {@code version}: the same executable. */
    private static Path scalerVersion(Path dir, String version) throws IOException {
        return version(dir, "sample-scaler", version);
    }

    /** A copy of {@code component}'s bundle whose contract says {@code version}: the same executable. */
    private static Path version(Path dir, String component, String version) throws IOException {
        Path in = org.arflex.it.Components.jar(component);
        Path out = dir.resolve(component + "-" + version + ".jar");
        String entry = "OSGI-INF/arflex/" + component + ".xml";
        boolean found = false;
        try (java.util.zip.ZipFile z = new java.util.zip.ZipFile(in.toFile());
                java.util.zip.ZipOutputStream zo = new java.util.zip.ZipOutputStream(Files.newOutputStream(out))) {
            for (java.util.zip.ZipEntry e : java.util.Collections.list(z.entries())) {
                byte[] b = z.getInputStream(e).readAllBytes();
                if (e.getName().equals(entry)) {
                    String xml = new String(b, StandardCharsets.UTF_8);
                    String now = xml.replaceFirst("name=\"" + component + "\" version=\"[^\"]+\"",
                            "name=\"" + component + "\" version=\"" + version + "\"");
                    assertFalse(now.equals(xml), "the contract's version was not rewritten");
                    b = now.getBytes(StandardCharsets.UTF_8);
                    found = true;
                }
                zo.putNextEntry(new java.util.zip.ZipEntry(e.getName()));
                zo.write(b);
                zo.closeEntry();
            }
        }
        assertTrue(found, entry + " in " + in);
        return out;
    }

    private static String sha256(Path f) throws IOException {
        try {
            return java.util.HexFormat.of().formatHex(java.security.MessageDigest.getInstance("SHA-256")
                    .digest(Files.readAllBytes(f)));
        } catch (java.security.NoSuchAlgorithmException e) {
            throw new IllegalStateException(e);
        }
    }

    @Test
    @Order(9)
    void theProgressEndpointAnswersOnlyTheConsolesUser() {
        String rest = "/arflex-changesets/api/changeset-progress";
        List<String> answered = new ArrayList<>();
        int tries = 0;
        String wrong = "Basic " + java.util.Base64.getEncoder().encodeToString("arflex:admin".getBytes(StandardCharsets.UTF_8));
        for (String prefix : PREFIXES) {
            for (String auth : new String[] {null, wrong}) {
                HttpRequest.Builder b = HttpRequest.newBuilder(URI.create(rt.base() + prefix + rest)).GET()
                        .header("Origin", EVIL);
                if (auth != null) {
                    b.header("Authorization", auth);
                }
                HttpResponse<String> r = send(b, false);
                tries++;
                int st = r == null ? -1 : r.statusCode();
                if ((st >= 200 && st < 300) || (r != null && r.body().contains("\"progress\""))) {
                    answered.add(prefix + (auth == null ? " no credentials" : " wrong credentials") + " -> " + st);
                }
                if (prefix.equals("/system/console")) {
                    assertEquals(401, st, prefix + ": " + (r == null ? "" : r.body()));
                }
            }
        }
        System.out.println("ChangeSetConsoleIT: " + tries + " reads of the progress without the console's credentials, "
                + answered.size() + " answered");
        assertTrue(answered.isEmpty(), "answered: " + answered);
        // the console's user reads it: JSON, not sniffed, not shared with another origin
        HttpResponse<String> ok = send(HttpRequest.newBuilder(URI.create(rt.base() + PAGE + "/api/changeset-progress"))
                .GET().header("Origin", EVIL), true);
        assertEquals(200, ok.statusCode(), ok.body());
        assertEquals("nosniff", ok.headers().firstValue("X-Content-Type-Options").orElse(null));
        assertTrue(ok.headers().firstValue("Access-Control-Allow-Origin").isEmpty(), ok.headers().toString());
        Map<String, Object> p = Json.object(ok.body());
        assertEquals(true, p.get("drcr"));
        @SuppressWarnings("unchecked")
        Map<String, Object> last = (Map<String, Object>) p.get("progress");
        assertNotNull(last, "the sets applied above: " + ok.body());
        assertEquals(false, last.get("running"));
        assertEquals("committed", last.get("outcome"), ok.body());
        // a write to it is no endpoint, and is refused before one is looked for
        HttpResponse<String> post = post("/system/console", rest, Map.of(), "Origin", rt.base(), token);
        assertTrue(post.statusCode() >= 400, post.statusCode() + " " + post.body());
    }

    @Test
    @Order(10)
    void thePageShowsAnUpdatesShadowRunAndWindowLiveToItsOutcome() throws IOException {
        Browser.requireInstalled();
        assertEquals("ACTIVE", state("sample-scaler"), "the scaler the page installed runs");
        long scalerPid = pid("sample-scaler");
        Path work = Path.of(System.getProperty("arflex.it.work", "target/it")).resolve("changeset-console").toAbsolutePath();
        Path jar = scalerVersion(Files.createDirectories(work.resolve("versions")), "1.0.1-live");
        // 10 ms cycles: 300 shadow cycles take 3 s, the window 200 cycles 2 s
        String set = "update sample-scaler " + jar.toUri() + " " + sha256(jar)
                + " shadow 300 tolerance y.value 0.000001 window 200";
        Path shots = Path.of(System.getProperty("arflex.screenshots", "target/screenshots"));
        try (Browser b = Browser.start(work.resolve("chromedriver-progress.log"))) {
            b.cdp("Network.enable", Map.of());
            b.cdp("Network.setExtraHTTPHeaders", Map.of("headers", Map.of("Authorization", rt.basicAuth())));
            b.open(rt.base() + PAGE);
            b.await("the page", WAIT, () -> textOf(b, "#arflex-cs-history-table"), b::url);
            planInTheBrowser(b, set);
            b.await("the plan admitted", WAIT, () -> {
                String t = textOf(b, "#arflex-cs-admission");
                return t != null && t.startsWith("Admitted") ? t : null;
            }, b::source);
            b.click(b.findAll("#arflex-cs-apply").get(0));
            // live: the shadow run with its cycles counting and the worst deviation so far
            String shadow = b.await("the shadow run shown live, its cycles counting", WAIT, () -> {
                String phase = (String) b.js("const e = document.getElementById('arflex-cs-live-box');"
                        + " return e && e.dataset.running === 'true' ? e.dataset.phase : null;");
                String cycle = (String) b.js("const e = document.getElementById('arflex-cs-live-cycles');"
                        + " return e ? e.dataset.cycle : null;");
                return "shadow".equals(phase) && cycle != null && Long.parseLong(cycle) > 0
                        ? textOf(b, "#arflex-cs-live-box") : null;
            }, b::source);
            b.screenshot(shots.resolve("changesets-progress-shadow.png"));
            assertTrue(shadow.contains("Applying now: update sample-scaler"), shadow);
            assertTrue(shadow.contains("of 300 (sample-scaler)"), shadow);
            assertTrue(shadow.contains("update sample-scaler: shadow run of pid"), shadow);
            assertEquals(scalerPid, pid("sample-scaler"), "nothing switched during the shadow run");
            String window = b.await("the rollback window shown live", WAIT, () -> {
                String phase = (String) b.js("const e = document.getElementById('arflex-cs-live-box');"
                        + " return e ? e.dataset.phase + '/' + e.dataset.running : null;");
                return "window/true".equals(phase) || (phase != null && phase.startsWith("done/"))
                        ? phase + " " + textOf(b, "#arflex-cs-live-box") : null;
            }, b::source);
            System.out.println("ChangeSetConsoleIT: after the shadow run the page showed: " + window);
            String done = b.await("the outcome shown live", WAIT, () -> {
                String phase = (String) b.js("const e = document.getElementById('arflex-cs-live-box');"
                        + " return e ? e.dataset.phase + '/' + e.dataset.outcome : null;");
                return phase != null && phase.startsWith("done/") ? phase : null;
            }, b::source);
            b.screenshot(shots.resolve("changesets-progress-done.png"));
            assertEquals("done/committed", done, textOf(b, "#arflex-cs-live-box"));
            @SuppressWarnings("unchecked")
            List<String> phases = (List<String>) b.js("return Array.from(document.querySelectorAll("
                    + "'#arflex-cs-live-phases li')).map(e => e.dataset.phase);");
            assertEquals(List.of("checking", "preparing", "shadow", "switching", "window", "bundles", "done"), phases);
        }
        // the endpoint says the same, and the new version runs
        Map<String, Object> p = Json.object(rt.get(PAGE + "/api/changeset-progress", true).body());
        @SuppressWarnings("unchecked")
        Map<String, Object> last = (Map<String, Object>) p.get("progress");
        assertEquals("committed", last.get("outcome"), String.valueOf(p));
        assertTrue(String.valueOf(last.get("why")).contains("update sample-scaler: passed its shadow run of"), String.valueOf(p));
        RuntimeUnderTest.awaitCondition("the new version running", WAIT,
                () -> pid("sample-scaler") != scalerPid && "ACTIVE".equals(state("sample-scaler")));
        // the shell says the same: arflex:change progress, its output in the runtime's log
        rt.gogo("arflex:change progress");
        RuntimeUnderTest.awaitCondition("arflex:change progress answered", WAIT,
                () -> rt.tail().contains("outcome: committed: update sample-scaler: passed its shadow run of 3"));
        assertTrue(rt.tail().contains("(phases checking > preparing > shadow > switching > window > bundles > done)\n"
                + "outcome: committed: update sample-scaler: passed its shadow run of 3"),
                rt.tail());
    }

    /** The page's row of each update (D60): component, phase, cycle, cycles, worst, verdict, as its data attributes say. */
    @SuppressWarnings("unchecked")
    private static List<Map<String, String>> updateRows(Browser b) {
        return (List<Map<String, String>>) b.js("return Array.from(document.querySelectorAll("
                + "'#arflex-cs-live-updates tr[data-component]')).map(e => ({component: e.dataset.component,"
                + " phase: e.dataset.phase, cycle: e.dataset.cycle, cycles: e.dataset.cycles, worst: e.dataset.worst,"
                + " verdict: e.dataset.verdict, text: e.innerText}));");
    }

    @Test
    @Order(11)
    @SuppressWarnings("unchecked")
    void aSetOfTwoUpdatesShowsARowForEachToItsOutcome() throws IOException {
        Browser.requireInstalled();
        RuntimeUnderTest.awaitCondition("counter and scaler running", WAIT,
                () -> "ACTIVE".equals(state("sample-counter")) && "ACTIVE".equals(state("sample-scaler")));
        long counterPid = pid("sample-counter");
        long scalerPid = pid("sample-scaler");
        Path dir = Files.createDirectories(Path.of(System.getProperty("arflex.it.work", "target/it"))
                .resolve("changeset-console").resolve("versions-two").toAbsolutePath());
        Path counter = version(dir, "sample-counter", "1.0.1-two");
        Path scaler = scalerVersion(dir, "1.0.2-two");
        // the counter without a shadow run (its sine's phase is its own), the scaler with one; 10 ms cycles
        String set = "update sample-counter " + counter.toUri() + " " + sha256(counter) + " window 200\n"
                + "update sample-scaler " + scaler.toUri() + " " + sha256(scaler)
                + " shadow 300 tolerance y.value 0.000001 window 200";
        Path work = Path.of(System.getProperty("arflex.it.work", "target/it")).resolve("changeset-console").toAbsolutePath();
        Path shots = Path.of(System.getProperty("arflex.screenshots", "target/screenshots"));
        try (Browser b = Browser.start(work.resolve("chromedriver-two.log"))) {
            b.cdp("Network.enable", Map.of());
            b.cdp("Network.setExtraHTTPHeaders", Map.of("headers", Map.of("Authorization", rt.basicAuth())));
            b.open(rt.base() + PAGE);
            b.await("the page", WAIT, () -> textOf(b, "#arflex-cs-history-table"), b::url);
            planInTheBrowser(b, set);
            b.await("the plan admitted", WAIT, () -> {
                String t = textOf(b, "#arflex-cs-admission");
                return t != null && t.startsWith("Admitted") ? t : null;
            }, b::source);
            b.click(b.findAll("#arflex-cs-apply").get(0));
            // live: the scaler's row counts its shadow cycles while the counter's waits for the switch
            List<Map<String, String>> shadow = b.await("the scaler's shadow run in its row", WAIT, () -> {
                List<Map<String, String>> rows = updateRows(b);
                return rows.size() == 2 && "shadow".equals(rows.get(1).get("phase"))
                        && Long.parseLong(rows.get(1).get("cycle")) > 0 ? rows : null;
            }, b::source);
            b.screenshot(shots.resolve("changesets-progress-two-shadow.png"));
            System.out.println("ChangeSetConsoleIT: two updates, in the scaler's shadow run: " + shadow);
            assertEquals(List.of("sample-counter", "sample-scaler"), shadow.stream().map(r -> r.get("component")).toList(),
                    "the rows in the set's order");
            assertEquals("", shadow.get(0).get("phase"), "the counter has no shadow run: " + shadow);
            assertEquals("300", shadow.get(1).get("cycles"));
            assertTrue(shadow.get(1).get("text").contains(" of 300"), shadow.toString());
            assertEquals(counterPid, pid("sample-counter"), "nothing switched during the shadow run");
            assertEquals(scalerPid, pid("sample-scaler"), "nothing switched during the shadow run");
            // both windows, each in its own row
            List<Map<String, String>> windows = b.await("both windows in their rows", WAIT, () -> {
                List<Map<String, String>> rows = updateRows(b);
                return rows.size() == 2 && rows.stream().allMatch(r -> "window".equals(r.get("phase"))) ? rows : null;
            }, b::source);
            System.out.println("ChangeSetConsoleIT: two updates, in their windows: " + windows);
            String done = b.await("the outcome", WAIT, () -> {
                String phase = (String) b.js("const e = document.getElementById('arflex-cs-live-box');"
                        + " return e ? e.dataset.phase + '/' + e.dataset.outcome : null;");
                return phase != null && phase.startsWith("done/") ? phase : null;
            }, b::source);
            b.screenshot(shots.resolve("changesets-progress-two-done.png"));
            assertEquals("done/committed", done, textOf(b, "#arflex-cs-live-box"));
            List<Map<String, String>> rows = updateRows(b);
            System.out.println("ChangeSetConsoleIT: two updates, the outcome: " + rows);
            assertEquals(2, rows.size(), "the rows stay with the outcome: " + rows);
            for (Map<String, String> r : rows) {
                assertEquals("committed", r.get("verdict"), rows.toString());
                assertEquals("window", r.get("phase"), rows.toString());
                assertEquals("200", r.get("cycles"), rows.toString());
                assertTrue(Long.parseLong(r.get("cycle")) >= 200, "its last counters: " + rows);
            }
            assertEquals("", rows.get(0).get("worst"), "no shadow run, no deviation: " + rows);
            assertFalse(rows.get(1).get("worst").isEmpty(), "the scaler's shadow run's worst deviation kept: " + rows);
            // the history's newest row: each update as the DRCR kept it (D62)
            List<Map<String, String>> kept = b.await("the history's row with each update", WAIT, () -> {
                List<Map<String, String>> h = (List<Map<String, String>>) b.js("const r = document.querySelector("
                        + "'#arflex-cs-history-table tr[data-index=\"0\"]'); return r ? Array.from(r.querySelectorAll("
                        + "'div.arflex-cs-history-update')).map(e => ({component: e.dataset.component, phase: e.dataset.phase,"
                        + " cycle: e.dataset.cycle, cycles: e.dataset.cycles, worst: e.dataset.worst,"
                        + " verdict: e.dataset.verdict, text: e.innerText})) : [];");
                return h.size() == 2 ? h : null;
            }, b::source);
            System.out.println("ChangeSetConsoleIT: two updates, the history's row: " + kept);
            assertEquals(List.of("sample-counter", "sample-scaler"), kept.stream().map(r -> r.get("component")).toList());
            for (Map<String, String> r : kept) {
                assertEquals("committed", r.get("verdict"), kept.toString());
                assertEquals("200", r.get("cycles"), kept.toString());
            }
            assertFalse(kept.get(1).get("worst").isEmpty(), kept.toString());
        }
        // the endpoint's history: the same entries
        List<Map<String, Object>> entries = (List<Map<String, Object>>) history().get(0).get("entries");
        assertEquals(List.of("sample-counter", "sample-scaler"), entries.stream().map(u -> u.get("component")).toList());
        assertEquals(List.of("committed", "committed"), entries.stream().map(u -> u.get("verdict")).toList());
        assertEquals("y.value", entries.get(1).get("worstField"), String.valueOf(entries));
        // the endpoint says the same
        Map<String, Object> p = Json.object(rt.get(PAGE + "/api/changeset-progress", true).body());
        Map<String, Object> last = (Map<String, Object>) p.get("progress");
        List<Map<String, Object>> updates = (List<Map<String, Object>>) last.get("updates");
        assertEquals(List.of("sample-counter", "sample-scaler"), updates.stream().map(u -> u.get("component")).toList());
        assertNull(updates.get(0).get("worstField"), String.valueOf(updates));
        assertEquals("y.value", updates.get(1).get("worstField"), String.valueOf(updates));
        assertTrue(String.valueOf(updates.get(1).get("why")).startsWith("update sample-scaler: committed: the new version ran"),
                String.valueOf(updates));
        RuntimeUnderTest.awaitCondition("both new versions running", WAIT,
                () -> pid("sample-counter") != counterPid && pid("sample-scaler") != scalerPid);
        // the shell: a line per update
        rt.gogo("arflex:change progress");
        RuntimeUnderTest.awaitCondition("arflex:change progress answered with a line per update", WAIT,
                () -> rt.tail().contains("update sample-scaler: rollback window, cycle "));
        String tail = rt.tail();
        assertTrue(tail.matches("(?s).*\nupdate sample-counter: rollback window, cycle \\d+ of 200; committed\n"
                + "update sample-scaler: rollback window, cycle \\d+ of 200, worst deviation in shadow y\\.value \\S+ "
                + "\\(tolerance 1\\.0E-6\\); committed.*"), tail);
        // and its history (D62): the same lines, kept
        rt.gogo("arflex:change history 1");
        RuntimeUnderTest.awaitCondition("arflex:change history answered", WAIT,
                () -> rt.tail().contains("1 of the "));
        String history = rt.tail().substring(rt.tail().lastIndexOf("1 of the "));
        assertTrue(history.matches("(?s)1 of the \\d+ change sets applied in this runtime, newest first\n"
                + "\\S+ \\S+ UTC  change set: update sample-counter .*\n  outcome: committed\n"
                + "  update sample-counter: rollback window, cycle \\d+ of 200; committed\n"
                + "  update sample-scaler: rollback window, cycle \\d+ of 200, worst deviation in shadow y\\.value \\S+ "
                + "\\(tolerance 1\\.0E-6\\); committed\n  prepared in .*"), history);
    }
}
