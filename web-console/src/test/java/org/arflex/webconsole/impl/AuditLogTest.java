package org.arflex.webconsole.impl;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertNull;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.nio.file.attribute.PosixFilePermissions;
import java.time.Clock;
import java.time.Instant;
import java.time.ZoneOffset;
import java.util.List;
import java.util.Map;
import java.util.stream.Stream;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;

/** The console's audit log: format, escaping, permissions, rotation, reading back. */
class AuditLogTest {
    private static final Clock CLOCK = Clock.fixed(Instant.parse("2026-11-25T10:00:00Z"), ZoneOffset.UTC);

    @TempDir
    Path tmp;

    @Test
    void anEntryIsOneJsonLineWithWhoWhatWhenAndResult() throws Exception {
        AuditLog log = new AuditLog(tmp.resolve("home/console-audit.log"), 4096, 2, CLOCK);
        log.record("arflex", "127.0.0.1", "POST", "/system/console/bundles/42", Map.of("action", "uninstall"), 200, null);
        List<String> lines = Files.readAllLines(log.file());
        assertEquals(1, lines.size());
        assertEquals("{\"time\":\"2026-11-25T10:00:00Z\",\"user\":\"arflex\",\"remote\":\"127.0.0.1\",\"method\":\"POST\","
                + "\"path\":\"/system/console/bundles/42\",\"params\":{\"action\":\"uninstall\"},\"status\":200,\"reason\":null}",
                lines.get(0));
    }

    @Test
    void nothingIsCreatedBeforeTheFirstEntry() {
        AuditLog log = new AuditLog(tmp.resolve("home/console-audit.log"));
        assertFalse(Files.exists(log.file()));
        assertFalse(Files.exists(tmp.resolve("home")));
    }

    @Test
    void fileIs0600AndAFolderItCreates0700WhateverTheModeBefore() throws Exception {
        Path file = tmp.resolve("new/console-audit.log");
        new AuditLog(file, 4096, 2, CLOCK).record("u", "r", "POST", "/p", Map.of(), 200, null);
        assertEquals("rw-------", PosixFilePermissions.toString(Files.getPosixFilePermissions(file)));
        assertEquals("rwx------", PosixFilePermissions.toString(Files.getPosixFilePermissions(file.getParent())));
        // A file found readable by others (an older version, a hand edit) is made private again.
        Files.setPosixFilePermissions(file, PosixFilePermissions.fromString("rw-rw-rw-"));
        new AuditLog(file, 4096, 2, CLOCK).record("u", "r", "POST", "/p", Map.of(), 200, null);
        assertEquals("rw-------", PosixFilePermissions.toString(Files.getPosixFilePermissions(file)));
    }

    @Test
    void newlinesAndQuotesCannotForgeAnotherEntry() throws Exception {
        AuditLog log = new AuditLog(tmp.resolve("console-audit.log"), 4096, 2, CLOCK);
        String forged = "x\n{\"time\":\"2020-01-01T00:00:00Z\",\"user\":\"admin\",\"status\":200}";
        log.record("arflex", "127.0.0.1", "POST", "/system/console/" + forged, Map.of("name", forged), 403, forged);
        List<String> lines = Files.readAllLines(log.file());
        assertEquals(1, lines.size(), "one line per entry, whatever the values hold");
        List<AuditLog.Entry> back = log.recent(10);
        assertEquals(1, back.size());
        assertEquals("/system/console/" + forged, back.get(0).path());
        assertEquals(forged, back.get(0).params().get("name"));
        assertEquals(403, back.get(0).status());
    }

    @Test
    void longValuesAreCutAndSaySo() {
        AuditLog log = new AuditLog(tmp.resolve("console-audit.log"), 4096, 2, CLOCK);
        AuditLog.Entry e = log.record("u", "r", "POST", "/p", Map.of("value", "v".repeat(5000)), 200, null);
        assertTrue(e.params().get("value").endsWith("…(5000 chars)"), e.params().get("value"));
        assertTrue(e.params().get("value").length() < 300);
    }

    @Test
    void rotatesBeforeTheLimitAndKeepsOnlySoManyFiles() throws Exception {
        Path file = tmp.resolve("console-audit.log");
        AuditLog log = new AuditLog(file, 1024, 2, CLOCK);
        for (int i = 0; i < 100; i++) {
            log.record("arflex", "127.0.0.1", "POST", "/system/console/bundles/" + i, Map.of("action", "stop"), 200, null);
        }
        try (Stream<Path> s = Files.list(tmp)) {
            assertEquals(List.of("console-audit.log", "console-audit.log.1", "console-audit.log.2"),
                    s.map(p -> p.getFileName().toString()).sorted().toList());
        }
        for (Path p : List.of(file, log.rotated(1), log.rotated(2))) {
            assertTrue(Files.size(p) <= 1024, p + " " + Files.size(p));
            assertEquals("rw-------", PosixFilePermissions.toString(Files.getPosixFilePermissions(p)));
        }
        // Newest first, across the files, without gaps.
        List<AuditLog.Entry> recent = log.recent(1000);
        assertEquals("/system/console/bundles/99", recent.get(0).path());
        for (int i = 1; i < recent.size(); i++) {
            int a = Integer.parseInt(recent.get(i - 1).path().substring(24));
            int b = Integer.parseInt(recent.get(i).path().substring(24));
            assertEquals(a - 1, b);
        }
        assertTrue(recent.size() < 100, "the oldest entries were dropped with the oldest file");
        assertEquals(5, log.recent(5).size());
    }

    @Test
    void appendsToWhatIsThereAndShowsADamagedLine() throws Exception {
        Path file = tmp.resolve("console-audit.log");
        Files.writeString(file, "not json\n", StandardCharsets.UTF_8);
        AuditLog log = new AuditLog(file, 4096, 2, CLOCK);
        log.record("arflex", "127.0.0.1", "POST", "/system/console/configMgr/x", Map.of(), 302, null);
        List<AuditLog.Entry> r = log.recent(10);
        assertEquals(2, r.size());
        assertEquals(302, r.get(0).status());
        assertEquals("?", r.get(1).method());
        assertTrue(r.get(1).reason().contains("not json"));
        assertNull(r.get(1).time());
    }

    @Test
    void anUnwritableLogDoesNotFailTheRequest() throws Exception {
        Path blocker = Files.writeString(tmp.resolve("file"), "x");
        AuditLog log = new AuditLog(blocker.resolve("console-audit.log"), 4096, 2, CLOCK);
        AuditLog.Entry e = log.record("u", "r", "POST", "/p", Map.of(), 200, null);
        assertEquals(200, e.status());
    }
}
