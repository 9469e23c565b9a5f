package org.arflex.webconsole;

import static org.junit.jupiter.api.Assertions.assertFalse;

import java.io.IOException;
import java.nio.file.Files;
import java.nio.file.Path;
import java.time.Duration;
import java.util.List;
import java.util.Map;
import org.openqa.selenium.By;
import org.openqa.selenium.OutputType;
import org.openqa.selenium.WebElement;
import org.openqa.selenium.chrome.ChromeDriver;
import org.openqa.selenium.support.ui.ExpectedConditions;
import org.openqa.selenium.support.ui.WebDriverWait;

/**
 * What the console tests do on the pages of a {@link ConsoleFixture}'s Chromium: log in, open
 * a page, wait for an element or its text, click through Deploy, post as the page does, take
 * screenshots (to {@code arflex.screenshots}). Every wait has a deadline ({@link #WAIT}).
 */
final class ConsolePages {
    static final Duration WAIT = Duration.ofSeconds(30);
    private final ConsoleFixture fx;

    ConsolePages(ConsoleFixture fx) {
        this.fx = fx;
    }

    ChromeDriver driver() {
        return fx.driver();
    }

    /** A wait of {@link #WAIT} on the browser. */
    WebDriverWait waiting() {
        return new WebDriverWait(driver(), WAIT);
    }

    /** Logs the browser in: the Web Console uses HTTP Basic authentication. */
    void login() {
        driver().executeCdpCommand("Network.enable", Map.of());
        driver().executeCdpCommand("Network.setExtraHTTPHeaders", Map.of("headers", Map.of("Authorization", fx.rt().basicAuth())));
    }

    void open(String labelAndQuery) {
        driver().get(fx.rt().base() + "/system/console/" + labelAndQuery);
    }

    WebElement await(By by) {
        return waiting().until(ExpectedConditions.visibilityOfElementLocated(by));
    }

    void awaitText(By by, String text) {
        waiting().until(ExpectedConditions.textToBePresentInElementLocated(by, text));
    }

    /** The component page's answer to command @what ("start: done" or why not), or null after @wait. */
    String commandAnswer(String what, Duration wait) {
        try {
            return new WebDriverWait(driver(), wait).until(d -> {
                String t = d.findElement(By.id("arflex-component-status")).getText();
                return t.contains(what + ":") ? t : null;
            });
        } catch (org.openqa.selenium.TimeoutException e) {
            return null;
        }
    }

    void shot(String name) throws IOException {
        Files.write(fx.screenshots().resolve(name + ".png"), driver().getScreenshotAs(OutputType.BYTES));
    }

    /**
     * Waits until the element's text contains {@code text}; on timeout fails naming the text it
     * last showed. Returns the text.
     */
    String awaitElementText(By by, String text) {
        String[] seen = {null};
        try {
            waiting().until(d -> {
                List<WebElement> e = d.findElements(by);
                seen[0] = e.isEmpty() ? null : e.get(0).getText();
                return seen[0] != null && seen[0].contains(text);
            });
        } catch (org.openqa.selenium.TimeoutException e) {
            throw new AssertionError("waited " + WAIT.toSeconds() + " s for " + by + " to show \"" + text
                    + "\"; it shows: " + (seen[0] == null ? "(no such element)" : "\"" + seen[0] + "\""), e);
        }
        return seen[0];
    }

    /** Waits until {@code attr} of the element is a number >= min; returns it. */
    long awaitAtLeast(By by, String attr, long min) {
        long[] seen = {Long.MIN_VALUE};
        waiting().until(d -> {
            String v = d.findElement(by).getAttribute(attr);
            if (v == null || v.isBlank()) {
                return false;
            }
            seen[0] = Long.parseLong(v);
            return seen[0] >= min;
        });
        return seen[0];
    }

    /** Waits until {@code attr} of the element differs from {@code old} (and is set); returns it. */
    String awaitChange(By by, String attr, String old) {
        String[] seen = {null};
        waiting().until(d -> {
            seen[0] = d.findElement(by).getAttribute(attr);
            return seen[0] != null && !seen[0].isBlank() && !seen[0].equals(old);
        });
        return seen[0];
    }

    /** A POST from the console page itself (its origin, its CSRF token): "status body". */
    String pagePost(String api) {
        return (String) driver().executeAsyncScript(
                "const done = arguments[arguments.length - 1]; const app = document.getElementById('arflex-app');"
                + "fetch(app.dataset.root + '/api/' + arguments[0], {method: 'POST', credentials: 'same-origin',"
                + " headers: {'Accept': 'application/json', 'X-Arflex-Csrf': app.dataset.csrf}})"
                + ".then(r => r.text().then(t => done(r.status + ' ' + t))).catch(e => done('error ' + e));", api);
    }

    /**
     * Clears the field and types {@code text} into it, again while the page redraws it (the
     * element found is replaced or not yet interactable) until it took the text or {@link #WAIT}
     * passed.
     */
    void typeInto(By by, String text) {
        waiting().ignoring(org.openqa.selenium.StaleElementReferenceException.class)
                .ignoring(org.openqa.selenium.ElementNotInteractableException.class).until(d -> {
                    WebElement e = d.findElement(by);
                    e.clear();
                    e.sendKeys(text);
                    return text.equals(e.getAttribute("value"));
                });
    }

    /** Opens the Deploy page, types the jar's {@code file:} URL and the pin, and clicks Fetch. */
    void fetchOnDeploy(Path jar, String pin) {
        open("arflex-deploy");
        await(By.id("arflex-url")).sendKeys(jar.toUri().toString());
        driver().findElement(By.id("arflex-sha256")).sendKeys(pin);
        driver().findElement(By.id("arflex-fetch")).click();
    }

    /** Uploads a jar on the Deploy page, checks its plan is shown, confirms and waits for the status. */
    void uploadAndConfirm(Path jar, String statusText) {
        open("arflex-deploy");
        await(By.id("arflex-upload-file")).sendKeys(jar.toString());
        driver().findElement(By.id("arflex-upload")).click();
        assertFalse(await(By.id("arflex-plan-text")).getText().isBlank(), "a plan is shown before confirming");
        driver().findElement(By.id("arflex-confirm")).click();
        awaitElementText(By.id("arflex-deploy-status"), statusText);
    }
}
