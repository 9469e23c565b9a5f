package org.arflex.webconsole;

import static org.junit.jupiter.api.Assertions.assertEquals;
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
import java.nio.file.Path;
import java.time.Duration;
import java.util.ArrayList;
import java.util.List;
import java.util.Map;
import java.util.regex.Matcher;
import java.util.regex.Pattern;

/**
 * The Change sets page's endpoints (D46) as its page uses them, over HTTP with the console's
 * login and one session (cookies, the page's CSRF token read on construction), and the page
 * itself in a {@link Browser}: what the change-set console tests share.
 */
final class ChangeSetApi {
    static final Duration WAIT = Duration.ofSeconds(60);
    static final String PAGE = "/system/console/arflex-changesets";
    static final String EVIL = "http://evil.example";
    /** The apply URL as an attacker may spell it: every one names the console (ConsolePath). */
    static final String[] PREFIXES = {"/system/console", "/%73ystem/console", "/%2573ystem/console",
        "/SYSTEM/console", "/system/./console", "/system/x/../console", "/system/console;x=1", "//system/console",
        "/system%2fconsole", "/system/%63onsole", "/%2e/system/console"};
    private final RuntimeUnderTest rt;
    private final HttpClient http = HttpClient.newBuilder().connectTimeout(Duration.ofSeconds(5))
            .cookieHandler(new CookieManager()).build();
    /** The page's CSRF token of this session. */
    final String token;

    ChangeSetApi(RuntimeUnderTest rt) {
        this.rt = rt;
        String page = send(HttpRequest.newBuilder(URI.create(rt.base() + PAGE)).GET(), true).body();
        Matcher m = Pattern.compile("data-csrf='([^']+)'").matcher(page);
        assertTrue(m.find(), "no CSRF token on the Change sets page: " + page);
        token = m.group(1);
        assertTrue(page.contains("data-page='changesets'"), page);
    }

    HttpResponse<String> send(HttpRequest.Builder b, boolean auth) {
        if (auth) {
            b.header("Authorization", rt.basicAuth());
        }
        try {
            return http.send(b.timeout(Duration.ofSeconds(30)).build(), HttpResponse.BodyHandlers.ofString());
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
    HttpResponse<String> post(String prefix, String rest, Map<String, String> fields, String header, String value,
                              String csrf) {
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
    Map<String, Object> legit(String endpoint, Map<String, String> fields, int expect) {
        HttpResponse<String> r = post("/system/console", "/arflex-changesets/api/" + endpoint, fields, "Origin", rt.base(),
                token);
        assertNotNull(r, "no answer to " + endpoint);
        assertEquals(expect, r.statusCode(), endpoint + ": " + r.body());
        return Json.object(r.body());
    }

    Map<String, Object> status() {
        HttpResponse<String> r = send(HttpRequest.newBuilder(URI.create(rt.base() + PAGE + "/api/changesets")).GET(), true);
        assertEquals(200, r.statusCode(), r.body());
        return Json.object(r.body());
    }

    List<Map<String, Object>> history() {
        @SuppressWarnings("unchecked")
        List<Map<String, Object>> h = (List<Map<String, Object>>) status().get("history");
        return h;
    }

    @SuppressWarnings("unchecked")
    Map<String, Object> awaitOutcome() {
        Map<String, Object>[] seen = new Map[1];
        RuntimeUnderTest.awaitCondition("the outcome of the apply", WAIT, () -> {
            Map<String, Object> s = status();
            seen[0] = s;
            return s.get("applying") == null && s.get("last") != null;
        });
        return (Map<String, Object>) seen[0].get("last");
    }

    // ---- the page in Chromium

    /** A Chromium holding the console's login on the Change sets page, its history table drawn. */
    Browser openPage(Path driverLog) throws IOException {
        Browser b = Browser.start(driverLog);
        try {
            b.cdp("Network.enable", Map.of());
            b.cdp("Network.setExtraHTTPHeaders", Map.of("headers", Map.of("Authorization", rt.basicAuth())));
            b.open(rt.base() + PAGE);
            b.await("the page", WAIT, () -> textOf(b, "#arflex-cs-history-table"), b::url);
            return b;
        } catch (RuntimeException | Error e) {
            b.close();
            throw e;
        }
    }

    /** Sets the page's actions as typed (the input event included) and clicks Plan. */
    static void planInTheBrowser(Browser b, String actions) {
        b.js("const t = document.getElementById('arflex-cs-actions'); t.value = arguments[0];"
                + "t.dispatchEvent(new Event('input'));", actions);
        b.click(b.findAll("#arflex-cs-plan-btn").get(0));
    }

    /** Plans {@code actions} on the page, waits until the plan is admitted and clicks Apply. */
    static void applyInTheBrowser(Browser b, String actions) {
        planInTheBrowser(b, actions);
        b.await("the plan admitted", WAIT, () -> {
            String t = textOf(b, "#arflex-cs-admission");
            return t != null && t.startsWith("Admitted") ? t : null;
        }, b::source);
        b.click(b.findAll("#arflex-cs-apply").get(0));
    }

    /** Waits until the live box shows the set done; returns "done/<outcome>". */
    static String awaitLiveOutcome(Browser b, String what) {
        return b.await(what, WAIT, () -> {
            String phase = (String) b.js("const e = document.getElementById('arflex-cs-live-box');"
                    + " return e ? e.dataset.phase + '/' + e.dataset.outcome : null;");
            return phase != null && phase.startsWith("done/") ? phase : null;
        }, b::source);
    }

    /** The text of the first element matching {@code css}, read in one call (the page redraws parts every second). */
    static String textOf(Browser b, String css) {
        return (String) b.js("const e = document.querySelector(arguments[0]); return e ? e.innerText : null;", css);
    }

    /** The page's row of each update (D60): component, phase, cycle, cycles, worst, verdict, as its data attributes say. */
    @SuppressWarnings("unchecked")
    static List<Map<String, String>> updateRows(Browser b) {
        return (List<Map<String, String>>) b.js("return Array.from(document.querySelectorAll("
                + "'#arflex-cs-live-updates tr[data-component]')).map(e => ({component: e.dataset.component,"
                + " phase: e.dataset.phase, cycle: e.dataset.cycle, cycles: e.dataset.cycles, worst: e.dataset.worst,"
                + " verdict: e.dataset.verdict, text: e.innerText}));");
    }
}
