package org.arflex.webconsole;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertNotNull;
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
 * outcomes and the refusals.
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
}
