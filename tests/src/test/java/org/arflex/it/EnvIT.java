package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.file.Files;
import java.nio.file.Path;
import org.junit.jupiter.api.Test;

/**
 * Issue 30 findings 5 and 8 and issue 32 end to end (D80), through {@link EnvDoors}: trusted
 * folders and their jars are checked for owner and mode (a second local user, created by the
 * test and removed after it, plays the attacker), RT halves get an explicit environment (no
 * console password, nothing of the runtime's own), and a shipped half has no fault mode unless
 * the runtime was started for tests.
 */
class EnvIT {

    static final long T = CellIT.T;

    private static Path work() {
        return Path.of(System.getProperty("arflex.it.work"));
    }

    private static void assertRefused(CodeDoors.Attempt a) {
        System.out.println("EnvIT: " + a.door() + ": " + (a.succeeded() ? "SUCCEEDED" : "refused") + "  " + a.detail());
        assertFalse(a.succeeded(), a.door() + ": " + a.detail());
    }

    @Test
    void aJarAnotherUserCopiedIntoAWorldWritableTrustedFolderDoesNotRun() throws Exception {
        try (EnvDoors.LocalUser u = EnvDoors.LocalUser.create()) {
            CodeDoors.Attempt a = EnvDoors.othersWritableTrustedFolder(work(), u);
            assertRefused(a);
            assertTrue(a.detail().contains("is writable by group or others (0777)"), a.detail());
        }
    }

    @Test
    void aTrustedJarAnotherUserOwnsIsRefusedBeforeAndAfterItsRewrite() throws Exception {
        try (EnvDoors.LocalUser u = EnvDoors.LocalUser.create()) {
            CodeDoors.Attempt a = EnvDoors.jarOwnedByAnotherUserRewritten(work(), u);
            assertRefused(a);
            assertTrue(a.detail().contains("is owned by uid " + u.uid + " (" + u.name + ")"), a.detail());
        }
    }

    @Test
    void halvesGetNeitherTheConsolePasswordNorTheRuntimesOwnVariables() throws Exception {
        assertRefused(EnvDoors.consolePasswordInHalves());
    }

    @Test
    void strayFaultVariablesOfTheRuntimeDoNotReachItsHalves() throws Exception {
        assertRefused(EnvDoors.strayFaultInRuntimeEnvironment());
    }

    /**
     * Issue 32: a shipped half whose environment holds a fault (a script sets
     * ARFLEX_FAULT_START_ERRNO and runs the real counter, as the update tests' faulty versions
     * do) starts as usual under a runtime not started for tests, and says it ignored it.
     */
    @Test
    void aShippedHalfIgnoresItsFaultVariablesUnderARuntimeNotStartedForTests() throws Exception {
        try (Runtime rt = Runtime.withProperties("env-nohooks", "arflex.test.hooks=false")) {
            Path dir = Files.createDirectories(rt.dir.resolve("versions"));
            byte[] script = FaultyVersions.refusingStart(dir, Components.jar("sample-counter"), EnvDoors.EXE, 125, "EnvIT");
            Path jar = BundleCopies.copy(dir, Components.jar("sample-counter"), "counter-refuses-start",
                    java.util.Map.<String, java.util.function.UnaryOperator<byte[]>>of(EnvDoors.EXE, b -> script));
            int mark = rt.logMark();
            rt.installAndStart(jar);
            rt.awaitState("ACTIVE", T, EnvDoors.COMPONENT);
            assertTrue(rt.logSince(mark).stream().anyMatch(l -> l.contains("ARFLEX_FAULT_* ignored")), rt.tail());
        }
    }
}
