package org.arflex.drcr.impl.supervisor;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.HashMap;
import java.util.List;
import java.util.Map;
import java.util.Set;
import java.util.TreeSet;
import org.arflex.drcr.impl.abi.ControlBlock;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;

/**
 * Issue 30 finding 8 and issue 32 (D80): every RT half got the runtime's whole environment, the
 * console password and rt-core's test fault hooks included. A half now gets an explicit one:
 * the locale, the time zone, PATH and the data folder, and the test-hook marker only when the
 * runtime was started for tests.
 */
class HalfEnvironmentTest {

    private static Map<String, String> runtime() {
        Map<String, String> env = new HashMap<>();
        env.put("PATH", "/usr/bin:/bin");
        env.put("LANG", "C.UTF-8");
        env.put("LC_NUMERIC", "C");
        env.put("TZ", "UTC");
        env.put("ARFLEX_DATA_DIR", "/var/lib/arflex/data");
        env.put("ARFLEX_CONSOLE_PASSWORD", "s3cret");
        env.put("ARFLEX_CONSOLE_USER", "admin");
        env.put("ARFLEX_CONSOLE_KEYSTORE_PASSWORD", "ks");
        env.put("ARFLEX_FAULT_START_ERRNO", "125");
        env.put("ARFLEX_FAULT_NTH", "3");
        env.put("ARFLEX_TEST_HOOKS", "1");
        env.put("LD_PRELOAD", "/tmp/evil.so");
        env.put("AWS_SECRET_ACCESS_KEY", "x");
        env.put("HOME", "/root");
        return env;
    }

    @Test
    void aHalfGetsTheLocaleTimeZonePathAndDataFolderOnly() {
        Map<String, String> env = HalfEnvironment.of(runtime(), false);
        assertEquals(Map.of("PATH", "/usr/bin:/bin", "LANG", "C.UTF-8", "LC_NUMERIC", "C", "TZ", "UTC",
                "ARFLEX_DATA_DIR", "/var/lib/arflex/data"), env);
    }

    @Test
    void theTestHookMarkerIsTheDrcrsOwnNeverTheRuntimesVariable() {
        assertFalse(HalfEnvironment.of(runtime(), false).containsKey("ARFLEX_TEST_HOOKS"));
        Map<String, String> env = HalfEnvironment.of(runtime(), true);
        assertEquals("1", env.get("ARFLEX_TEST_HOOKS"));
        // even a test runtime passes no fault on: the tests' faulty versions set their own
        assertTrue(env.keySet().stream().noneMatch(k -> k.startsWith("ARFLEX_FAULT_") || k.startsWith("ARFLEX_CONSOLE_")),
                env.toString());
    }

    /**
     * The launcher spawns with that environment, not its own: a stand-in half writes the
     * environment it was started with (its /proc/self/environ) and exits. Run under surefire,
     * whose JVM has HOME, JAVA_HOME, MAVEN_* and more: none of them reaches the half.
     */
    @Test
    void theLauncherSpawnsAHalfWithTheExplicitEnvironmentNotItsOwn(@TempDir Path dir) throws Exception {
        Path seen = dir.resolve("environ");
        byte[] script = ("#!/bin/sh\ntr '\\0' '\\n' < /proc/$$/environ > " + seen + "\nexit 4\n")
                .getBytes(StandardCharsets.UTF_8);
        VerifiedExecutables exes = new VerifiedExecutables(dir, line -> { });
        Path exe = exes.extract(dir.resolve("native"), "env", () -> new java.io.ByteArrayInputStream(script));
        ProcessLauncher launcher = new ProcessLauncher(line -> { }, exes);
        RtLauncher.Spec spec = new RtLauncher.Spec("he" + ProcessHandle.current().pid(), "env", exe,
                new ControlBlock.Config(1_000_000, 1_000_000, 0, 0, 0, 0, 0, 0), List.of(), false, 5_000);
        IOException e = assertThrows(IOException.class, () -> launcher.launch(spec));
        assertTrue(e.getMessage().contains("exited with status 4"), e.getMessage());
        Set<String> names = new TreeSet<>();
        for (String line : Files.readAllLines(seen)) {
            names.add(line.substring(0, line.indexOf('=')));
        }
        Set<String> allowed = Set.of("PATH", "LANG", "LANGUAGE", "TZ", "ARFLEX_DATA_DIR");
        assertTrue(names.stream().allMatch(n -> allowed.contains(n) || n.startsWith("LC_")),
                "the half got the launcher's own environment: " + names);
        assertEquals(System.getenv("PATH") != null, names.contains("PATH"), names.toString());
    }
}
