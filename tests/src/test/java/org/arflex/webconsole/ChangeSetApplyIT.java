package org.arflex.webconsole;

import static org.arflex.webconsole.ChangeSetApi.EVIL;
import static org.arflex.webconsole.ChangeSetApi.PAGE;
import static org.arflex.webconsole.ChangeSetApi.PREFIXES;
import static org.arflex.webconsole.ChangeSetApi.planInTheBrowser;
import static org.arflex.webconsole.ChangeSetApi.textOf;
import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertNotNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.net.URI;
import java.net.http.HttpRequest;
import java.net.http.HttpResponse;
import java.nio.charset.StandardCharsets;
import java.nio.file.Path;
import java.time.Duration;
import java.util.ArrayList;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import java.util.regex.Pattern;
import org.junit.jupiter.api.BeforeAll;
import org.junit.jupiter.api.MethodOrderer;
import org.junit.jupiter.api.Order;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.TestMethodOrder;
import org.junit.jupiter.api.extension.RegisterExtension;

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
 * outcomes and the refusals. Then the page in Chromium plans and applies a third set; last,
 * the progress endpoint answers no one without the console's credentials, however its path
 * is spelt.
 */
@TestMethodOrder(MethodOrderer.OrderAnnotation.class)
class ChangeSetApplyIT {
    private static final Duration WAIT = ChangeSetApi.WAIT;
    @RegisterExtension
    static final ConsoleFixture FX = ConsoleFixture.runtime("changeset-apply").started("sample-counter").installed("sample-scaler");
    private static ChangeSetApi api;
    /** The plan id the dry run showed: the forged applies, the stale apply and the audit use it. */
    private static String shownPlanId;

    @BeforeAll
    static void session() {
        api = new ChangeSetApi(FX.rt());
    }

    @Test
    @Order(1)
    @SuppressWarnings("unchecked")
    void theDryRunShowsTheWholeSetAndChangesNothing() {
        long counterPid = FX.pid("sample-counter");
        Map<String, Object> r = api.legit("changeset-plan", Map.of("actions", "# the scaler joins\ninstall sample-scaler\n"), 200);
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
        assertEquals("INSTALLED", FX.state("sample-scaler"), "a dry run starts nothing");
        assertEquals(counterPid, FX.pid("sample-counter"));
        // a bad line is named before the DRCR is asked
        HttpResponse<String> bad = api.post("/system/console", "/arflex-changesets/api/changeset-plan",
                Map.of("actions", "install sample-scaler\ninstal sample-counter"), "Origin", FX.rt().base(), api.token);
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
            {"Origin", EVIL, api.token}, {"Referer", EVIL + "/page", api.token}, {null, null, api.token}, {"Origin", "null", api.token},
            {"Origin", FX.rt().base(), null}, {"Origin", FX.rt().base(), "forged-api.token"}, {"Sec-Fetch-Site", "cross-site", api.token},
        };
        String[] named = {"foreign Origin", "foreign Referer", "no Origin or Referer", "Origin null", "own Origin, no api.token",
            "own Origin, forged api.token", "Sec-Fetch-Site cross-site"};
        int tries = 0;
        List<String> accepted = new ArrayList<>();
        for (int h = 0; h < how.length; h++) {
            for (String prefix : PREFIXES) {
                HttpResponse<String> r = api.post(prefix, "/arflex-changesets/api/changeset-apply", fields, how[h][0], how[h][1],
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
        System.out.println("ChangeSetApplyIT: " + tries + " forged applies, " + accepted.size() + " accepted");
        assertTrue(accepted.isEmpty(), "accepted: " + accepted);
        Map<String, Object> s = api.status();
        assertEquals(null, s.get("applying"), "nothing is being applied");
        assertEquals(null, s.get("last"));
        assertTrue(api.history().isEmpty(), "the DRCR applied no set: " + api.history());
        assertEquals("INSTALLED", FX.state("sample-scaler"));
    }

    @Test
    @Order(3)
    void aPlanMadeStaleByAChangeOfTheCellIsRefusedOnApply() {
        HttpResponse<String> stop = api.post("/system/console", "/arflex-component/api/command?name=sample-counter&cmd=stop",
                Map.of(), "Origin", FX.rt().base(), api.token);
        assertEquals(200, stop.statusCode(), stop.body());
        RuntimeUnderTest.awaitCondition("sample-counter stopped", WAIT, () -> !"ACTIVE".equals(FX.state("sample-counter")));
        HttpResponse<String> r = api.post("/system/console", "/arflex-changesets/api/changeset-apply",
                Map.of("actions", "install sample-scaler", "plan", shownPlanId), "Origin", FX.rt().base(), api.token);
        assertEquals(409, r.statusCode(), r.body());
        assertTrue(r.body().contains("the cell changed since the plan was shown"), r.body());
        assertEquals("INSTALLED", FX.state("sample-scaler"), "nothing applied");
        assertTrue(api.history().isEmpty());
        HttpResponse<String> start = api.post("/system/console", "/arflex-component/api/command?name=sample-counter&cmd=start",
                Map.of(), "Origin", FX.rt().base(), api.token);
        assertEquals(200, start.statusCode(), start.body());
        RuntimeUnderTest.awaitCondition("sample-counter ACTIVE again", WAIT, () -> "ACTIVE".equals(FX.state("sample-counter")));
    }

    @Test
    @Order(4)
    void theSetIsAppliedAsPlannedAndItsOutcomeAndHistoryShown() {
        long counterPid = FX.pid("sample-counter");
        Map<String, Object> plan = api.legit("changeset-plan", Map.of("actions", "install sample-scaler"), 200);
        assertEquals(true, plan.get("admitted"));
        Map<String, Object> r = api.legit("changeset-apply", Map.of("actions", "install sample-scaler",
                "plan", (String) plan.get("planId")), 200);
        assertEquals("applying", r.get("state"));
        Map<String, Object> last = api.awaitOutcome();
        assertEquals("committed", last.get("outcome"), String.valueOf(last));
        assertEquals(true, last.get("planAsShown"), String.valueOf(last));
        assertEquals(true, last.get("applied"));
        RuntimeUnderTest.awaitCondition("sample-scaler ACTIVE", WAIT, () -> "ACTIVE".equals(FX.state("sample-scaler")));
        assertEquals(counterPid, FX.pid("sample-counter"), "the counter was not restarted");
        List<Map<String, Object>> h = api.history();
        assertEquals(1, h.size(), String.valueOf(h));
        assertEquals(List.of("install sample-scaler"), h.get(0).get("actions"));
        assertEquals("committed", h.get(0).get("outcome"));
        assertTrue(((Number) h.get(0).get("finishedMillis")).longValue() > 0);
        System.out.println("ChangeSetApplyIT: install sample-scaler: prepared in " + last.get("prepareMs")
                + " ms, switch turn " + last.get("switchUs") + " µs");
    }

    @Test
    @Order(5)
    @SuppressWarnings("unchecked")
    void aSecondSetUninstallsAndSetsAndTheHistoryListsBothNewestFirst() {
        long counterPid = FX.pid("sample-counter");
        String set = "uninstall sample-scaler\nset sample-counter amplitude 3.5";
        Map<String, Object> plan = api.legit("changeset-plan", Map.of("actions", set), 200);
        assertEquals(true, plan.get("admitted"), String.valueOf(plan));
        List<Map<String, Object>> steps = (List<Map<String, Object>>) ((Map<String, Object>) plan.get("parts")).get("steps");
        assertTrue(steps.stream().anyMatch(s -> "STOP".equals(s.get("op")) && "sample-scaler".equals(s.get("component"))),
                String.valueOf(plan.get("text")));
        api.legit("changeset-apply", Map.of("actions", set, "plan", (String) plan.get("planId")), 200);
        Map<String, Object> last = api.awaitOutcome();
        assertEquals(List.of("uninstall sample-scaler", "set sample-counter amplitude 3.5"), last.get("actions"));
        assertEquals("committed", last.get("outcome"), String.valueOf(last));
        RuntimeUnderTest.awaitCondition("sample-scaler INSTALLED again", WAIT, () -> "INSTALLED".equals(FX.state("sample-scaler")));
        assertEquals(counterPid, FX.pid("sample-counter"));
        String comp = FX.rt().get("/system/console/arflex-component/api/component?name=sample-counter", true).body();
        assertTrue(Pattern.compile("\"name\":\"amplitude\",\"type\":\"[A-Z]+\",\"value\":\"3\\.5\"").matcher(comp).find(), comp);
        List<Map<String, Object>> h = api.history();
        assertEquals(2, h.size(), String.valueOf(h));
        assertEquals(List.of("uninstall sample-scaler", "set sample-counter amplitude 3.5"), h.get(0).get("actions"));
        assertEquals(List.of("install sample-scaler"), h.get(1).get("actions"));
    }

    @Test
    @Order(6)
    @SuppressWarnings("unchecked")
    void theAuditLogHasTheAppliesTheirOutcomesAndTheRefusals() {
        String body = FX.rt().get("/system/console/arflex-audit/api/audit", true).body();
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
        // refused requests are sampled with each value cut to 32 characters (D81): the plan id is
        // recognised by its first 32 and its length, never written whole
        String sampledPlan = shownPlanId.substring(0, 32) + "…(" + shownPlanId.length() + " chars)";
        assertTrue(refused.stream().anyMatch(e -> sampledPlan.equals(((Map<String, Object>) e.get("params")).get("plan"))
                && "install sample-scaler".equals(((Map<String, Object>) e.get("params")).get("actions"))), body);
        assertTrue(entries.stream().anyMatch(e -> apply.equals(e.get("path")) && ((Number) e.get("status")).intValue() == 409
                && String.valueOf(e.get("reason")).startsWith("the cell changed since the plan was shown")), body);
    }

    @Test
    @Order(7)
    void thePageShowsThePlanAppliesItAndShowsTheOutcomeWithMarkupKeptAsText() throws IOException {
        Browser.requireInstalled();
        Path work = FX.rt().work;
        try (Browser b = api.openPage(work.resolve("chromedriver.log"))) {
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
            assertEquals("INSTALLED", FX.state("sample-scaler"), "nothing happens before the apply");
            b.click(b.findAll("#arflex-cs-apply").get(0));
            String outcome = b.await("the outcome", WAIT, () -> {
                String t = textOf(b, "#arflex-cs-outcome[data-outcome]");
                return t != null && t.startsWith("Last set applied here: install sample-scaler \u2014") ? t : null;
            }, b::source);
            assertEquals(null, textOf(b, "#arflex-cs-status .arflex-msg"), "the note 'Applying the set' is gone");
            assertTrue(outcome.contains("committed"), outcome);
            RuntimeUnderTest.awaitCondition("sample-scaler ACTIVE", WAIT, () -> "ACTIVE".equals(FX.state("sample-scaler")));
            b.await("three sets in the history", WAIT,
                    () -> b.findAll("#arflex-cs-history-table tr[data-outcome='committed']").size() == 3 ? Boolean.TRUE : null,
                    b::source);
            b.screenshot(Path.of(System.getProperty("arflex.screenshots", "target/screenshots")).resolve("changesets-outcome.png"));
        }
    }

    @Test
    @Order(8)
    void theProgressEndpointAnswersOnlyTheConsolesUser() {
        String rest = "/arflex-changesets/api/changeset-progress";
        List<String> answered = new ArrayList<>();
        int tries = 0;
        String wrong = "Basic " + java.util.Base64.getEncoder().encodeToString("arflex:admin".getBytes(StandardCharsets.UTF_8));
        for (String prefix : PREFIXES) {
            for (String auth : new String[] {null, wrong}) {
                HttpRequest.Builder b = HttpRequest.newBuilder(URI.create(FX.rt().base() + prefix + rest)).GET()
                        .header("Origin", EVIL);
                if (auth != null) {
                    b.header("Authorization", auth);
                }
                HttpResponse<String> r = api.send(b, false);
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
        System.out.println("ChangeSetApplyIT: " + tries + " reads of the progress without the console's credentials, "
                + answered.size() + " answered");
        assertTrue(answered.isEmpty(), "answered: " + answered);
        // the console's user reads it: JSON, not sniffed, not shared with another origin
        HttpResponse<String> ok = api.send(HttpRequest.newBuilder(URI.create(FX.rt().base() + PAGE + "/api/changeset-progress"))
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
        HttpResponse<String> post = api.post("/system/console", rest, Map.of(), "Origin", FX.rt().base(), api.token);
        assertTrue(post.statusCode() >= 400, post.statusCode() + " " + post.body());
    }
}
