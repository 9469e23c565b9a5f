package org.arflex.webconsole;

import static org.arflex.webconsole.ConsoleJars.cellJar;
import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.nio.file.Files;
import java.nio.file.Path;
import java.time.Duration;
import java.util.List;
import java.util.stream.Stream;
import org.junit.jupiter.api.MethodOrderer;
import org.junit.jupiter.api.Order;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.TestMethodOrder;
import org.junit.jupiter.api.extension.RegisterExtension;
import org.openqa.selenium.By;
import org.openqa.selenium.WebElement;

/**
 * Watching the running cell from the console's pages in headless Chromium, sample-counter and
 * sample-scaler running: a port's value plotted, the cell's tool-centre error preset (no
 * tcp-correction, then pointed at another port), the debug monitor installed, watched and
 * uninstalled with the others undisturbed; last the cell's own tcp-correction's toggle.
 */
@TestMethodOrder(MethodOrderer.OrderAnnotation.class)
class WebConsoleWatchIT {
    private static final Duration WAIT = ConsolePages.WAIT;
    @RegisterExtension
    static final ConsoleFixture FX = ConsoleFixture.withBrowser("webconsole-watch").loggedIn().started("sample-counter", "sample-scaler");
    private static final ConsolePages PAGES = FX.pages();

    @Test
    @Order(1)
    void aPortValuePlotShowsChangingValues() throws IOException {
        // The counter's sine (arflex.Sample state port `count`), read by the DRCR from a read-only mapping.
        String one = FX.rt().get("/system/console/arflex-component/api/port?name=sample-counter&port=count", true).body();
        assertTrue(one.contains("\"type\":\"arflex.Sample\"") && one.contains("\"name\":\"value\""), one);
        assertEquals(404, FX.rt().get("/system/console/arflex-component/api/port?name=sample-counter&port=nope", true).statusCode());
        assertEquals(400, FX.rt().get("/system/console/arflex-component/api/port?name=sample-counter&port=%3Cb%3E", true).statusCode());
        long pid = FX.pid("sample-counter");
        PAGES.open("arflex-component?name=sample-counter");
        PAGES.await(By.id("arflex-port-select"));
        PAGES.waiting().until(d -> "value".equals(
                new org.openqa.selenium.support.ui.Select(d.findElement(By.id("arflex-port-field"))).getFirstSelectedOption().getAttribute("value")));
        new org.openqa.selenium.support.ui.Select(PAGES.driver().findElement(By.id("arflex-port-select"))).selectByValue("count");
        PAGES.driver().findElement(By.id("arflex-port-plot-btn")).click();
        By plot = By.id("arflex-port-plot");
        PAGES.awaitAtLeast(plot, "data-samples", 2);
        String first = PAGES.driver().findElement(plot).getAttribute("data-last");
        String second = PAGES.awaitChange(plot, "data-last", first);
        String third = PAGES.awaitChange(plot, "data-last", second);
        assertFalse(first.equals(third) && first.equals(second), "the value changes: " + first + ", " + second + ", " + third);
        PAGES.waiting().until(d -> !d.findElements(By.cssSelector("#arflex-port-plot canvas")).isEmpty());
        PAGES.awaitText(By.id("arflex-port-last"), "count.value = ");
        // Any statistic of the stream on its own plot: the cycle counter grows.
        PAGES.waiting().until(d -> new org.openqa.selenium.support.ui.Select(
                d.findElement(By.id("arflex-stat-select"))).getOptions().size() > 5);
        new org.openqa.selenium.support.ui.Select(PAGES.driver().findElement(By.id("arflex-stat-select"))).selectByValue("cycles");
        By stat = By.id("arflex-stat-plot");
        PAGES.awaitAtLeast(stat, "data-samples", 1);
        long c0 = Long.parseLong(PAGES.driver().findElement(stat).getAttribute("data-last"));
        PAGES.waiting().until(d -> Long.parseLong(d.findElement(stat).getAttribute("data-last")) > c0);
        PAGES.driver().executeScript("arguments[0].scrollIntoView();", PAGES.driver().findElement(By.id("arflex-ports-live")));
        PAGES.shot("13-component-port-plot");
        assertEquals(pid, FX.pid("sample-counter"), "watching a port does not disturb its producer");
    }

    @Test
    @Order(2)
    void theCellPresetPlotsTheErrorPortOrSaysWhyNot() throws IOException {
        PAGES.open("arflex-cell");
        PAGES.awaitText(By.id("arflex-tcp-error-none"), "tcp-correction");
        // The same preset pointed at another Sample port (how another cell uses it): values drawn.
        PAGES.open("arflex-cell?error=sample-scaler.y");
        By plot = By.id("arflex-tcp-error-plot");
        PAGES.awaitAtLeast(plot, "data-samples", 2);
        PAGES.awaitChange(plot, "data-last", PAGES.driver().findElement(plot).getAttribute("data-last"));
        PAGES.awaitText(By.id("arflex-tcp-error-last"), "y = ");
        assertTrue(PAGES.driver().findElements(By.id("arflex-tcp-toggle")).isEmpty(), "no enable parameter, no toggle");
        PAGES.shot("14-cell-error-preset");
    }

    @Test
    @Order(3)
    void installTheDebugMonitorWatchAValueAndUninstallItWithTheOthersUndisturbed() throws IOException {
        long counterPid = FX.pid("sample-counter");
        long scalerPid = FX.pid("sample-scaler");
        assertTrue(counterPid > 0 && scalerPid > 0, FX.cell());
        PAGES.open("arflex-debug");
        PAGES.await(By.id("arflex-debug-jar"));
        PAGES.await(By.id("arflex-debug-none"));
        new org.openqa.selenium.support.ui.Select(PAGES.await(By.id("arflex-debug-target-0"))).selectByValue("sample-counter.count");
        new org.openqa.selenium.support.ui.Select(PAGES.driver().findElement(By.id("arflex-debug-target-1"))).selectByValue("sample-scaler.y");
        PAGES.driver().findElement(By.id("arflex-debug-plan")).click();
        assertFalse(PAGES.await(By.id("arflex-plan-text")).getText().isBlank(), "the plan is shown before confirming");
        assertEquals(null, FX.state("debug-monitor"), "nothing installed before confirming");
        PAGES.shot("15-debug-plan");
        PAGES.driver().findElement(By.id("arflex-debug-confirm")).click();
        RuntimeUnderTest.awaitCondition("debug-monitor Active", WAIT, () -> "ACTIVE".equals(FX.state("debug-monitor")));

        // Watch: the monitor republishes the counter's value; the page shows it change.
        By last = By.id("arflex-debug-m0-last");
        long i0 = PAGES.awaitAtLeast(last, "data-index", 0);
        String v0 = PAGES.driver().findElement(last).getAttribute("data-value");
        PAGES.awaitAtLeast(last, "data-index", i0 + 2);
        PAGES.awaitChange(last, "data-value", v0);
        PAGES.awaitAtLeast(By.id("arflex-debug-m1-last"), "data-index", 0);
        PAGES.awaitText(By.id("arflex-debug-m0-target"), "sample-counter.count");
        PAGES.awaitText(By.id("arflex-debug-m1-target"), "sample-scaler.y");
        // A smaller window: applied by the monitor's RT half, then min/max/mean arrive.
        // typed once the page lets it be (it redrew the field under the test once: "element not interactable")
        PAGES.typeInto(By.id("arflex-debug-window"), "5");
        PAGES.driver().findElement(By.id("arflex-debug-window-apply")).click();
        PAGES.awaitText(By.id("arflex-debug-status"), "window applied by the RT half: 5");
        PAGES.awaitAtLeast(By.id("arflex-debug-m0-mean"), "data-index", 0);
        // both read in one script: the page re-renders between two separate reads
        @SuppressWarnings("unchecked")
        List<Object> mm = (List<Object>) PAGES.driver().executeScript("return [document.getElementById('arflex-debug-m0-min')"
                + ".getAttribute('data-value'), document.getElementById('arflex-debug-m0-max').getAttribute('data-value')];");
        double min = Double.parseDouble(String.valueOf(mm.get(0)));
        double max = Double.parseDouble(String.valueOf(mm.get(1)));
        assertTrue(min <= max, min + " <= " + max);
        PAGES.waiting().until(d -> Long.parseLong(d.findElement(By.id("arflex-debug-plot")).getAttribute("data-samples")) > 2);
        PAGES.shot("16-debug-watching");
        assertEquals(counterPid, FX.pid("sample-counter"), "the watched counter keeps running (same pid)");
        assertEquals(scalerPid, FX.pid("sample-scaler"), "the watched scaler keeps running (same pid)");

        // Uninstall from the same page, after its plan.
        PAGES.driver().findElement(By.id("arflex-debug-uninstall")).click();
        assertFalse(PAGES.await(By.id("arflex-plan-text")).getText().isBlank());
        PAGES.driver().findElement(By.id("arflex-debug-confirm")).click();
        RuntimeUnderTest.awaitCondition("debug-monitor gone", WAIT, () -> FX.state("debug-monitor") == null);
        PAGES.await(By.id("arflex-debug-none"));
        PAGES.shot("17-debug-uninstalled");
        assertEquals("ACTIVE", FX.state("sample-counter"));
        assertEquals("ACTIVE", FX.state("sample-scaler"));
        assertEquals(counterPid, FX.pid("sample-counter"), "the counter was not restarted");
        assertEquals(scalerPid, FX.pid("sample-scaler"), "the scaler was not restarted");
        String prefix = "arflex." + FX.runtimeId() + ".debug-monitor.";
        RuntimeUnderTest.awaitCondition("the monitor's segments removed", WAIT, () -> {
            try (Stream<Path> st = Files.list(Path.of("/dev/shm"))) {
                return st.noneMatch(p -> p.getFileName().toString().startsWith(prefix));
            } catch (IOException e) {
                throw new java.io.UncheckedIOException(e);
            }
        });
    }

    @Test
    @Order(4)
    void theCellPresetTogglesTheCorrectionOfTheRealTcpCorrection() throws IOException {
        // The cell's own trajectory (role=motion, its inputs optional) and tcp-correction, from the
        // assembly's cell/; without vision no error is measured, but the preset and its toggle work.
        Path trajectory = cellJar("trajectory", "org.arflex.cell.trajectory");
        Path correction = cellJar("tcp-correction", "org.arflex.cell.tcpcorrection");
        FX.rt().gogo("start " + trajectory.toUri());
        FX.rt().gogo("start " + correction.toUri());
        RuntimeUnderTest.awaitCondition("tcp-correction Active", Duration.ofSeconds(60),
                () -> "ACTIVE".equals(FX.state("tcp-correction")));
        String contract = FX.rt().get("/system/console/arflex-component/api/component?name=tcp-correction", true).body();
        // The cell's tcp-correction publishes its tool-centre error: without it the preset has
        // nothing to plot, and that is a broken cell bundle, not a pass.
        assertTrue(contract.contains("\"name\":\"error\",\"direction\":\"OUT\""),
                "tcp-correction has no output port 'error' for the preset to plot: " + contract);
        PAGES.open("arflex-cell");
        WebElement toggle = PAGES.await(By.id("arflex-tcp-toggle"));
        By plot = By.id("arflex-tcp-error-plot");
        String before = FX.paramValue("tcp-correction", "enable");
        assertEquals("true", before, "correction enabled by default");
        PAGES.waiting().until(d -> "on".equals(d.findElement(plot).getAttribute("data-correction")));
        PAGES.awaitText(By.id("arflex-tcp-error-last"), "correction on");
        toggle.click();
        PAGES.awaitText(By.id("arflex-tcp-status"), "enable applied by the RT half: false");
        PAGES.waiting().until(d -> "off".equals(d.findElement(plot).getAttribute("data-correction")));
        assertEquals("false", FX.paramValue("tcp-correction", "enable"));
        PAGES.awaitText(By.id("arflex-tcp-error-last"), "correction off");
        PAGES.shot("18-cell-tcp-preset-correction-off");
        PAGES.driver().findElement(By.id("arflex-tcp-toggle")).click();
        PAGES.waiting().until(d -> "on".equals(d.findElement(plot).getAttribute("data-correction")));
        assertEquals("true", FX.paramValue("tcp-correction", "enable"));
    }
}
