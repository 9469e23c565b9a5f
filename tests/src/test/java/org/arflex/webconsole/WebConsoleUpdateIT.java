package org.arflex.webconsole;

import static org.arflex.webconsole.ConsoleJars.sample;
import static org.arflex.webconsole.ConsoleJars.sha256;
import static org.arflex.webconsole.ConsoleJars.withContract;
import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.net.URI;
import java.net.http.HttpRequest;
import java.net.http.HttpResponse;
import java.nio.file.Path;
import java.time.Duration;
import org.junit.jupiter.api.MethodOrderer;
import org.junit.jupiter.api.Order;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.TestMethodOrder;
import org.junit.jupiter.api.extension.RegisterExtension;
import org.openqa.selenium.By;

/**
 * Updates and resets from the console's pages in headless Chromium, sample-counter and
 * sample-scaler running: an update the DRCR cannot plan (no update URL, a wrong pin) shows why
 * and offers no Confirm; an update after the DRCR's plan restarts only the updated component;
 * a restarted moving component is released by the reset buttons of its page and of the cell.
 */
@TestMethodOrder(MethodOrderer.OrderAnnotation.class)
class WebConsoleUpdateIT {
    private static final Duration WAIT = ConsolePages.WAIT;
    @RegisterExtension
    static final ConsoleFixture FX = ConsoleFixture.withBrowser("webconsole-update").loggedIn().started("sample-counter", "sample-scaler");
    private static final ConsolePages PAGES = FX.pages();

    @Test
    @Order(1)
    void anUpdateTheDrcrCannotPlanShowsWhyAndOffersNoConfirm() throws IOException {
        long scalerPid = FX.pid("sample-scaler");
        assertTrue(scalerPid > 0, FX.cell());
        // No update URL in the contract: the DRCR's reason instead of a plan, and no Confirm.
        PAGES.open("arflex-deploy");
        PAGES.await(By.id("arflex-update-sample-scaler")).click();
        String error = PAGES.awaitElementText(By.id("arflex-plan-error"), "cannot plan the update of sample-scaler");
        assertEquals("cannot plan the update of sample-scaler: its contract has no update URL", error.strip());
        assertTrue(PAGES.driver().findElements(By.id("arflex-confirm")).isEmpty(), "no Confirm for a plan the DRCR could not make");
        assertTrue(PAGES.driver().findElements(By.id("arflex-plan-text")).isEmpty(), "no plan text either");
        PAGES.shot("19-deploy-update-no-url");
        // The JSON endpoint: CSRF-checked like every POST; from the page, a 409 naming why.
        HttpResponse<String> forged = FX.rt().send(HttpRequest.newBuilder(URI.create(FX.rt().base()
                + "/system/console/arflex-deploy/api/plan-update?name=sample-scaler"))
                .header("Origin", FX.rt().base()).POST(HttpRequest.BodyPublishers.noBody()), true);
        assertEquals(403, forged.statusCode(), forged.body());
        String r = PAGES.pagePost("plan-update?name=sample-scaler");
        assertEquals("409 {\"error\":\"cannot plan the update of sample-scaler: its contract has no update URL\"}", r);
        assertTrue(PAGES.pagePost("plan-update?name=nope").startsWith("404 "), "an unknown component is 404");

        // A contract that pins the wrong hash: the dry run downloads and checks it, names both hashes.
        Path v2 = withContract(sample("scaler"), FX.variant("scaler-1.1.0.jar"),
                xml -> xml.replace("version=\"1.0.0\"", "version=\"1.1.0\""));
        String wrong = "0".repeat(64);
        PAGES.uploadAndConfirm(scalerWithUpdate("scaler-wrong-pin.jar", v2, wrong), "updated");
        RuntimeUnderTest.awaitCondition("the scaler with the wrong pin Active", WAIT,
                () -> "ACTIVE".equals(FX.state("sample-scaler")) && FX.componentJson("sample-scaler").contains(wrong));
        long pinnedPid = FX.pid("sample-scaler");
        PAGES.open("arflex-deploy");
        PAGES.await(By.id("arflex-update-sample-scaler")).click();
        error = PAGES.awaitElementText(By.id("arflex-plan-error"), "SHA-256");
        assertTrue(error.startsWith("cannot plan the update of sample-scaler: update not installed, the old version keeps running:")
                && error.contains(v2.toUri().toString()) && error.contains(sha256(v2)) && error.contains(wrong), error);
        assertTrue(PAGES.driver().findElements(By.id("arflex-confirm")).isEmpty(), "no Confirm after a hash mismatch");
        PAGES.shot("20-deploy-update-wrong-pin");
        assertEquals("1.0.0", FX.contractVersion("sample-scaler"), "nothing installed");
        assertEquals(pinnedPid, FX.pid("sample-scaler"), "a failed plan restarts nothing");
        assertEquals("ACTIVE", FX.state("sample-scaler"));
    }

    @Test
    @Order(2)
    void updateAComponentFromTheDeployPageAfterTheDrcrsPlan() throws IOException {
        Path v2 = withContract(sample("scaler"), FX.variant("scaler-1.1.0.jar"),
                xml -> xml.replace("version=\"1.0.0\"", "version=\"1.1.0\""));
        String pin = sha256(v2);
        PAGES.uploadAndConfirm(scalerWithUpdate("scaler-1.0.0-updatable.jar", v2, pin), "updated");
        RuntimeUnderTest.awaitCondition("the updatable scaler Active", WAIT,
                () -> "ACTIVE".equals(FX.state("sample-scaler")) && FX.componentJson("sample-scaler").contains(pin));
        assertEquals("1.0.0", FX.contractVersion("sample-scaler"));
        long scalerPid = FX.pid("sample-scaler");
        long counterPid = FX.pid("sample-counter");

        PAGES.open("arflex-deploy");
        PAGES.await(By.id("arflex-update-sample-scaler")).click();
        String plan = PAGES.await(By.id("arflex-plan-text")).getText();
        // The DRCR's dry run: from where, hash checked, and the replacement restarts only the scaler.
        assertTrue(plan.startsWith("update of sample-scaler from " + v2.toUri() + " (sha256 verified)"), plan);
        assertTrue(plan.lines().anyMatch(l -> l.matches("\\s*RESTART\\s+sample-scaler\\s.*")), plan);
        assertTrue(plan.lines().noneMatch(l -> l.matches("\\s*(STOP|RESTART)\\s+sample-counter\\s.*")), plan);
        assertEquals(pin, PAGES.driver().findElement(By.id("arflex-update-sha")).getText());
        assertTrue(PAGES.driver().findElement(By.id("arflex-plan")).getText().contains("Plan: update sample-scaler 1.0.0"));
        assertEquals("1.0.0", FX.contractVersion("sample-scaler"), "a plan installs nothing");
        assertEquals(scalerPid, FX.pid("sample-scaler"), "a plan restarts nothing");
        PAGES.shot("21-deploy-update-plan");

        PAGES.driver().findElement(By.id("arflex-confirm")).click();
        String report = PAGES.awaitElementText(By.id("arflex-deploy-status"), "updated to 1.1.0");
        assertEquals("sample-scaler: updated to 1.1.0 from " + v2.toUri() + " (sha256 verified)", report.strip());
        RuntimeUnderTest.awaitCondition("sample-scaler 1.1.0 Active with a new pid", WAIT,
                () -> "ACTIVE".equals(FX.state("sample-scaler")) && FX.pid("sample-scaler") > 0
                        && FX.pid("sample-scaler") != scalerPid && "1.1.0".equals(FX.contractVersion("sample-scaler")));
        assertEquals(counterPid, FX.pid("sample-counter"), "the provider is not restarted");
        assertTrue(PAGES.driver().findElements(By.id("arflex-confirm")).isEmpty(), "the plan is gone once confirmed");
        PAGES.open("arflex-deploy");
        PAGES.awaitText(By.cssSelector("tr[data-component='sample-scaler']"), "ACTIVE");
        PAGES.shot("22-deploy-updated");
    }

    @Test
    @Order(3)
    void theResetButtonReleasesARestartedMovingComponent() throws IOException {
        // The counter as a component that moves hardware: after a crash the DRCR restarts it held
        // (no motion) until an operator resets it.
        Path moving = withContract(sample("counter"), FX.variant("counter-moving.jar"),
                xml -> xml.replace("movesHardware=\"false\"", "movesHardware=\"true\"").replace("<ports>",
                        "<ports><in name=\"safety\" type=\"arflex.SafetyState\" typeVersion=\"1.0\" method=\"state\" safety=\"true\"/>"));
        PAGES.uploadAndConfirm(moving, "updated");
        RuntimeUnderTest.awaitCondition("the moving counter Active", WAIT, () -> "ACTIVE".equals(FX.state("sample-counter"))
                && FX.componentJson("sample-counter").contains("\"movesHardware\":true"));
        assertEquals(Boolean.FALSE, FX.awaitingReset("sample-counter"), "the first start needs no reset");
        long pid = FX.pid("sample-counter");
        ProcessHandle.of(pid).ifPresent(ProcessHandle::destroyForcibly);
        RuntimeUnderTest.awaitCondition("sample-counter restarted", WAIT, () -> {
            long now = FX.pid("sample-counter");
            return now > 0 && now != pid && "ACTIVE".equals(FX.state("sample-counter"));
        });
        assertEquals(Boolean.TRUE, FX.awaitingReset("sample-counter"), FX.componentJson("sample-counter"));
        long restartedPid = FX.pid("sample-counter");
        // Held: the RT half cycles, its output does not move.
        RuntimeUnderTest.awaitCondition("the new RT half cycling", WAIT, () -> FX.cycles("sample-counter") > 20);
        String held = FX.portFields("sample-counter", "count");
        long c0 = FX.cycles("sample-counter");
        RuntimeUnderTest.awaitCondition("20 more cycles", WAIT, () -> FX.cycles("sample-counter") > c0 + 20);
        assertEquals(held, FX.portFields("sample-counter", "count"), "a restarted moving component holds its output");

        PAGES.open("arflex-component?name=sample-counter");
        PAGES.awaitElementText(By.id("arflex-summary"), "restarted: waits for an operator reset before motion");
        // The live stream comes up although the sampler thread stopped while no page watched
        // (the Deploy page has no stream): its frames go on numbering from before.
        PAGES.awaitElementText(By.id("arflex-live-count"), "samples; cycles");
        PAGES.shot("23-component-awaiting-reset");
        PAGES.await(By.id("arflex-cmd-reset")).click();
        PAGES.awaitElementText(By.id("arflex-component-status"), "reset: done");
        RuntimeUnderTest.awaitCondition("the DRCR to clear awaitingReset", WAIT,
                () -> Boolean.FALSE.equals(FX.awaitingReset("sample-counter")));
        PAGES.waiting().until(d -> !d.findElement(By.id("arflex-summary")).getText()
                .contains("waits for an operator reset"));
        RuntimeUnderTest.awaitCondition("the output moving again after the reset", WAIT,
                () -> !held.equals(FX.portFields("sample-counter", "count")));
        PAGES.shot("24-component-reset");
        assertEquals(restartedPid, FX.pid("sample-counter"), "the reset does not restart the process");
        assertEquals("ACTIVE", FX.state("sample-counter"));

        // The same from the cell page's one button: everything that waits, and what it did.
        ProcessHandle.of(restartedPid).ifPresent(ProcessHandle::destroyForcibly);
        RuntimeUnderTest.awaitCondition("sample-counter restarted again, awaiting a reset", WAIT, () -> {
            long now = FX.pid("sample-counter");
            return now > 0 && now != restartedPid && Boolean.TRUE.equals(FX.awaitingReset("sample-counter"));
        });
        PAGES.open("arflex-cell");
        PAGES.await(By.id("arflex-reset-cell")).click();
        // everything that waits is reset (on a loaded machine that may be more than the counter)
        PAGES.waiting().until(d -> d.findElement(By.id("arflex-reset-cell-status")).getText().lines()
                .findFirst().filter(l -> l.matches("cell: reset (.+, )?sample-counter(, .+)?")).isPresent());
        RuntimeUnderTest.awaitCondition("the DRCR to clear awaitingReset after the cell reset", WAIT,
                () -> Boolean.FALSE.equals(FX.awaitingReset("sample-counter")));
        PAGES.shot("25-cell-reset");
    }

    private static final String CRITICALITY_3 = "<criticality>3</criticality>";

    /** The scaler whose contract names an update URL and pin (placed where the schema wants it). */
    private static Path scalerWithUpdate(String file, Path target, String pin) throws IOException {
        return withContract(sample("scaler"), FX.variant(file), xml -> xml.replace(CRITICALITY_3,
                CRITICALITY_3 + "<update url=\"" + target.toUri() + "\" sha256=\"" + pin + "\"/>"));
    }
}
