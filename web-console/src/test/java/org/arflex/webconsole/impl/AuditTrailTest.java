package org.arflex.webconsole.impl;

import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.file.Files;
import java.nio.file.Path;
import java.time.Duration;
import java.util.Map;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;

/** The security history under every flood at its worst: what it keeps, how fast it grows. */
class AuditTrailTest {
    @TempDir
    Path tmp;

    @Test
    void everyFloodAtItsWorstGrowsTheHistoryByLittleEnoughToHoldHoursAndKeepsAnEarlierChange() throws Exception {
        LoginLimiterTest.TestClock clock = new LoginLimiterTest.TestClock();
        AuditLog main = new AuditLog(tmp.resolve("console-audit.log"), 1 << 20, 3, clock);
        AuditLog security = new AuditLog(tmp.resolve(AuditTrail.SECURITY_FILE), AuditTrail.SECURITY_FILE_BYTES,
                AuditLog.DEFAULT_KEEP, clock);
        AuditTrail trail = new AuditTrail(main, security, clock);
        trail.request("arflex", "127.0.0.1", "POST", "/system/console/bundles/42", Map.of("action", "uninstall"), 200, null);
        String longParam = "v".repeat(300);
        LoginLimiter.Lock lock = new LoginLimiter.Lock("client 127.0.0.1", Duration.ofMinutes(5), 99);
        int minutes = 30;
        for (int m = 0; m < minutes; m++) {
            // every minute: more keys than are told apart, with the longest values a field keeps
            for (int i = 0; i < 40; i++) {
                String origin = "http://" + "o".repeat(80) + i + ".example";
                String client = "127.0." + (i / 250) + "." + (i % 250);
                trail.refused(origin, "arflex", client, "POST", "/system/console/" + longParam, Map.of("action", longParam,
                        "name", longParam), 403, "cross-site request refused " + longParam);
                trail.loginFailed("u".repeat(300), client, "/system/console/" + longParam);
                trail.loginLocked("u".repeat(300), client, "/system/console/" + longParam, lock);
            }
            clock.advance(Duration.ofMinutes(1));
        }
        trail.close();
        long bytes = 0;
        for (int i = 0; i <= AuditLog.DEFAULT_KEEP; i++) {
            Path p = i == 0 ? security.file() : security.rotated(i);
            bytes += Files.isRegularFile(p) ? Files.size(p) : 0;
        }
        long perMinute = bytes / minutes;
        long capacity = (AuditLog.DEFAULT_KEEP + 1) * AuditTrail.SECURITY_FILE_BYTES;
        System.out.printf("security history: %d bytes per minute of every flood at its worst; %d bytes hold %.1f h of it%n",
                perMinute, capacity, capacity / (double) perMinute / 60);
        assertTrue(security.recent(100_000).stream().anyMatch(e -> "/system/console/bundles/42".equals(e.path())),
                "the change was pushed out of the security history");
        assertTrue(capacity / perMinute >= 6 * 60, perMinute + " bytes a minute: the history holds less than 6 h of floods");
    }
}
