package org.arflex.webconsole;

import static org.arflex.webconsole.ConsoleJars.sample;
import static org.arflex.webconsole.ConsoleJars.sha256;
import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertNotNull;
import static org.junit.jupiter.api.Assertions.assertTrue;
import static org.junit.jupiter.api.Assertions.fail;

import java.io.IOException;
import java.nio.file.Files;
import java.nio.file.Path;
import java.time.Duration;
import java.util.Map;
import java.util.regex.Pattern;
import org.junit.jupiter.api.MethodOrderer;
import org.junit.jupiter.api.Order;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.TestMethodOrder;
import org.junit.jupiter.api.extension.RegisterExtension;
import org.openqa.selenium.By;
import org.openqa.selenium.WebElement;

/**
 * Authoring and deploying through the console's pages in headless Chromium, in order on one
 * runtime as an engineer would use it: the contract editor (the error at the field, then
 * saved), install by upload and from a pinned {@code file:} URL with the plan shown, a
 * parameter applied by the RT half, the graph, uninstall after its plan, and why a component
 * is not Active with stop and start from its page.
 */
@TestMethodOrder(MethodOrderer.OrderAnnotation.class)
class WebConsoleDeployIT {
    private static final Duration WAIT = ConsolePages.WAIT;
    @RegisterExtension
    static final ConsoleFixture FX = ConsoleFixture.withBrowser("webconsole-deploy").loggedIn();
    private static final ConsolePages PAGES = FX.pages();

    @Test
    @Order(1)
    void contractEditorShowsTheErrorAtTheFieldThenSaves() throws IOException {
        PAGES.open("arflex-contract");
        PAGES.await(By.id("arflex-new")).click();
        WebElement name = PAGES.await(By.id("arflex-f-name"));
        name.clear();
        name.sendKeys("demo-filter");
        // Markup typed into a field stays text everywhere (XML and form), never becomes an element.
        WebElement description = PAGES.driver().findElement(By.cssSelector("input[data-field='description']"));
        description.sendKeys("<img id='xss' src='x' onerror='window.arflexXss=1'>");
        PAGES.driver().findElement(By.id("arflex-from-xml")).click();
        assertTrue(PAGES.driver().findElements(By.id("xss")).isEmpty());
        assertEquals(null, PAGES.driver().executeScript("return window.arflexXss === undefined ? null : window.arflexXss;"));
        assertTrue(PAGES.driver().findElement(By.id("arflex-xml")).getAttribute("value").contains("&lt;img id='xss'"));
        PAGES.await(By.id("arflex-add-port")).click();
        PAGES.await(By.id("arflex-add-prop")).click();
        WebElement period = PAGES.await(By.id("arflex-f-timing-period"));
        period.clear();
        period.sendKeys("fast");
        assertTrue(PAGES.driver().findElement(By.id("arflex-xml")).getAttribute("value").contains("period=\"fast\""));
        PAGES.await(By.id("arflex-validate")).click();
        PAGES.waiting().until(d -> d.findElement(By.id("arflex-f-timing-period")).getAttribute("class").contains("arflex-invalid"));
        WebElement err = PAGES.driver().findElement(By.xpath("//input[@id='arflex-f-timing-period']/following-sibling::span[@class='arflex-field-error']"));
        assertTrue(err.getText().contains("fast"), "error shown at the period field: " + err.getText());
        PAGES.shot("03-contract-error-at-field");
        // Saving an invalid contract is refused with the same problems. The status still shows the
        // validation's problems: emptied first, so that what is awaited is the save's own answer
        // (a save answered late once overwrote the next validation's "Valid" here).
        PAGES.driver().executeScript("document.getElementById('arflex-contract-status').replaceChildren();");
        PAGES.await(By.id("arflex-save")).click();
        PAGES.awaitText(By.id("arflex-contract-status"), "problem");
        assertFalse(Files.exists(FX.rt().home.resolve("contracts/demo-filter.xml")));

        period = PAGES.driver().findElement(By.id("arflex-f-timing-period"));
        period.clear();
        period.sendKeys("5ms");
        PAGES.driver().findElement(By.id("arflex-validate")).click();
        PAGES.awaitText(By.id("arflex-contract-status"), "Valid");
        PAGES.driver().findElement(By.id("arflex-save")).click();
        PAGES.awaitText(By.id("arflex-contract-status"), "Saved to");
        PAGES.shot("04-contract-saved");
        Path saved = FX.rt().home.resolve("contracts/demo-filter.xml");
        assertTrue(Files.isRegularFile(saved));
        assertTrue(Files.readString(saved).contains("period=\"5ms\""));
    }

    @Test
    @Order(2)
    void installTheCounterByUploadWithThePlanShown() throws IOException {
        Path counter = sample("counter");
        PAGES.open("arflex-deploy");
        PAGES.await(By.id("arflex-upload-file")).sendKeys(counter.toString());
        PAGES.driver().findElement(By.id("arflex-upload")).click();
        WebElement plan = PAGES.await(By.id("arflex-plan-text"));
        assertFalse(plan.getText().isBlank(), "a plan is shown before confirming");
        assertEquals(sha256(counter), PAGES.driver().findElement(By.id("arflex-staged-sha")).getText());
        assertEquals(null, FX.state("sample-counter"), "nothing installed before confirming");
        PAGES.shot("05-deploy-plan-upload");
        PAGES.driver().findElement(By.id("arflex-confirm")).click();
        PAGES.awaitText(By.id("arflex-deploy-status"), "installed");
        RuntimeUnderTest.awaitCondition("sample-counter Active", WAIT, () -> "ACTIVE".equals(FX.state("sample-counter")));
    }

    @Test
    @Order(3)
    void installTheScalerFromAFileUrlWithItsPinnedHash() throws IOException {
        Path scaler = sample("scaler");
        // A wrong pin is refused and nothing is installed.
        PAGES.fetchOnDeploy(scaler, "0".repeat(64));
        PAGES.awaitText(By.id("arflex-deploy-status"), "not the pinned");
        // http is refused.
        PAGES.driver().findElement(By.id("arflex-url")).clear();
        PAGES.driver().findElement(By.id("arflex-url")).sendKeys("http://127.0.0.1/x.jar");
        PAGES.driver().findElement(By.id("arflex-fetch")).click();
        PAGES.awaitText(By.id("arflex-deploy-status"), "only https or file");
        // The right pin gives the plan, then the install.
        PAGES.driver().findElement(By.id("arflex-url")).clear();
        PAGES.driver().findElement(By.id("arflex-url")).sendKeys(scaler.toUri().toString());
        PAGES.driver().findElement(By.id("arflex-sha256")).clear();
        PAGES.driver().findElement(By.id("arflex-sha256")).sendKeys(sha256(scaler));
        PAGES.driver().findElement(By.id("arflex-fetch")).click();
        assertFalse(PAGES.await(By.id("arflex-plan-text")).getText().isBlank());
        PAGES.shot("06-deploy-plan-url");
        PAGES.driver().findElement(By.id("arflex-confirm")).click();
        PAGES.awaitText(By.id("arflex-deploy-status"), "installed");
        RuntimeUnderTest.awaitCondition("sample-scaler Active", WAIT, () -> "ACTIVE".equals(FX.state("sample-scaler")));
        PAGES.open("arflex-cell");
        PAGES.awaitText(By.id("arflex-instances"), "sample-scaler");
        PAGES.waiting().until(d -> d.findElements(By.cssSelector("tr[data-component='sample-scaler'] .arflex-state-active")).size() == 1);
        PAGES.shot("07-cell-two-components");
    }

    @Test
    @Order(4)
    void changeAParameterAndSeeItAppliedByTheRtHalf() throws IOException {
        PAGES.open("arflex-component?name=sample-scaler");
        WebElement gain = PAGES.await(By.id("arflex-param-gain"));
        // Out of range: refused at the field.
        gain.clear();
        gain.sendKeys("99");
        PAGES.driver().findElement(By.id("arflex-apply-gain")).click();
        PAGES.waiting().until(d -> d.findElement(By.id("arflex-param-gain")).getAttribute("class").contains("arflex-invalid"));
        gain = PAGES.driver().findElement(By.id("arflex-param-gain"));
        gain.clear();
        gain.sendKeys("4.25");
        PAGES.driver().findElement(By.id("arflex-apply-gain")).click();
        PAGES.awaitText(By.id("arflex-component-status"), "applied by the RT half");
        PAGES.awaitText(By.id("arflex-applied-gain"), "4.25");
        // The live stream shows samples (server-sent events).
        PAGES.awaitText(By.id("arflex-live-count"), "samples");
        PAGES.awaitText(By.id("arflex-live-count"), "gain=4.25");
        // The RT half's wake-up latency histogram (StatsDTO, via the stream) is drawn.
        PAGES.awaitText(By.id("arflex-histogram-summary"), "p99.9");
        PAGES.waiting().until(d -> !d.findElements(By.cssSelector("#arflex-histogram-plot canvas")).isEmpty()
                && Long.parseLong(d.findElement(By.id("arflex-histogram")).getAttribute("data-samples")) > 0);
        String hist = FX.rt().get("/system/console/arflex-component/api/histogram?name=sample-scaler", true).body();
        assertTrue(Pattern.compile("\"binNs\":100,\"lowerEdgesNs\":\\[\\d+").matcher(hist).find(), hist);
        PAGES.shot("08-component-param-applied");
        String comp = FX.rt().get("/system/console/arflex-component/api/component?name=sample-scaler", true).body();
        assertTrue(Pattern.compile("\"name\":\"gain\",\"type\":\"[A-Z]+\",\"value\":\"4\\.25\"").matcher(comp).find(), comp);
    }

    @Test
    @Order(5)
    void graphShowsComponentsAndLinks() throws IOException {
        PAGES.open("arflex-graph");
        WebElement g = PAGES.await(By.id("arflex-graph"));
        PAGES.waiting().until(d -> "2".equals(g.getAttribute("data-nodes")));
        assertEquals("1", g.getAttribute("data-edges"));
        PAGES.shot("09-graph");
        // Clicking a component opens its page.
        @SuppressWarnings("unchecked")
        Map<String, Object> pos = (Map<String, Object>) PAGES.driver().executeScript(
                "const cy = arguments[0].arflexGraph; const n = cy.getElementById('sample-scaler');"
                + "return {x: n.renderedPosition().x, y: n.renderedPosition().y};", g);
        int w = g.getRect().getWidth();
        int h = g.getRect().getHeight();
        new org.openqa.selenium.interactions.Actions(PAGES.driver())
                .moveToElement(g, (int) (((Number) pos.get("x")).doubleValue() - w / 2.0),
                        (int) (((Number) pos.get("y")).doubleValue() - h / 2.0))
                .click().perform();
        PAGES.waiting().until(d -> d.getCurrentUrl().contains("arflex-component?name=sample-scaler"));
        PAGES.await(By.id("arflex-param-gain"));
    }

    @Test
    @Order(6)
    void uninstallWithThePlanShown() throws IOException {
        PAGES.open("arflex-deploy");
        PAGES.await(By.id("arflex-uninstall-sample-scaler")).click();
        assertFalse(PAGES.await(By.id("arflex-plan-text")).getText().isBlank());
        assertNotNull(FX.state("sample-scaler"), "still installed until confirmed");
        PAGES.shot("10-uninstall-plan");
        PAGES.driver().findElement(By.id("arflex-confirm")).click();
        PAGES.awaitText(By.id("arflex-deploy-status"), "uninstalled");
        RuntimeUnderTest.awaitCondition("sample-scaler gone", WAIT, () -> FX.state("sample-scaler") == null);
        assertEquals("ACTIVE", FX.state("sample-counter"), "the other component is not disturbed");
        PAGES.open("arflex-cell");
        PAGES.awaitText(By.id("arflex-instances"), "sample-counter");
        PAGES.shot("11-cell-after-uninstall");
    }

    @Test
    @Order(7)
    void theCellSaysWhyAComponentIsNotActiveAndStopStartWork() throws IOException {
        Path scaler = sample("scaler");
        PAGES.fetchOnDeploy(scaler, sha256(scaler));
        PAGES.await(By.id("arflex-confirm")).click();
        RuntimeUnderTest.awaitCondition("sample-scaler Active again", WAIT, () -> "ACTIVE".equals(FX.state("sample-scaler")));

        // Stop the provider: the consumer loses its input and the cell says why.
        PAGES.open("arflex-component?name=sample-counter");
        PAGES.await(By.id("arflex-cmd-stop")).click();
        // the stop's own answer: Felix's stop returns once the halves stopped (ContractExtender);
        // a start clicked while it has not is held by the bundle's lock
        commandAnswered("stop");
        RuntimeUnderTest.awaitCondition("sample-scaler not Active", WAIT,
                () -> !"ACTIVE".equals(FX.state("sample-scaler")));
        PAGES.open("arflex-cell");
        By reason = By.cssSelector("tr[data-component='sample-scaler'] .arflex-reason");
        // The resolver's reason for an explicit binding whose provider left the cell: the input,
        // the consumer and the provider's port, as the DRCR words it.
        String expected = "input 'x' of 'sample-scaler': explicit provider 'sample-counter.count' is not installed";
        String why = PAGES.awaitElementText(reason, expected);
        PAGES.shot("12-cell-why-not-active");
        assertEquals(expected, why.strip(), "the cell shows the DRCR's reason for the missing provider");

        // Start it again from its page: both Active.
        // A stopped bundle's component stays in the cell as INSTALLED, and its page says so.
        PAGES.open("arflex-component?name=sample-counter");
        PAGES.waiting().until(d -> d.findElement(By.id("arflex-summary")).getText().contains("INSTALLED"));
        PAGES.await(By.id("arflex-cmd-start")).click();
        // the console's own answer first: "start: done", or why not (a failure names it here).
        // No second click (D82): two full runs once saw this one unanswered, and a retry hid it.
        commandAnswered("start");
        RuntimeUnderTest.awaitCondition("both Active", WAIT,
                () -> "ACTIVE".equals(FX.state("sample-counter")) && "ACTIVE".equals(FX.state("sample-scaler")));
    }

    /**
     * Waits for the component page's answer to command {@code what} and asserts it is "done";
     * without one, fails with what the page showed and the runtime's threads (where the
     * request waits, if it reached the runtime).
     */
    private static void commandAnswered(String what) throws IOException {
        String answered = PAGES.commandAnswer(what, WAIT);
        if (answered == null) {
            PAGES.shot("no-answer-to-" + what);
            fail("the console did not answer the " + what + " click within " + WAIT.toSeconds() + " s; the page showed '"
                    + PAGES.driver().findElement(By.id("arflex-component-status")).getText() + "', summary '"
                    + PAGES.driver().findElement(By.id("arflex-summary")).getText().lines().findFirst().orElse("")
                    + "'\n--- runtime threads\n" + FX.rt().threadDump());
        }
        assertTrue(answered.contains(what + ": done"), "the console answered the " + what + " with: " + answered);
    }
}
