package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.file.Path;
import java.util.List;
import java.util.stream.Collectors;
import org.junit.jupiter.api.Test;

/**
 * Issue 16 findings 3, 5 and 6 against the real runtime, as an attacker on the same machine
 * would try them. The runtimes trust only their default folders ({@code bundle,cell,tools});
 * the attacker's jars lie in the build folder, outside them. Each door has a control that shows
 * the check can see it open (CodeDoors). The attack benchmark runs the same doors and more.
 */
class DoorsIT {

    private static String table(List<CodeDoors.Attempt> l) {
        return l.stream().map(a -> (a.succeeded() ? "OPEN " : "shut ") + a.door() + ": " + a.detail())
                .collect(Collectors.joining("\n"));
    }

    /** Finding 3: before the code gate every Felix door here started the counter's RT half. */
    @Test
    void everyUnverifiedCodeDoorIsShutAndSaysWhy() throws Exception {
        Path outside = Path.of(System.getProperty("arflex.it.work")).resolve("code-doors-attacker");
        try (Runtime rt = new Runtime("code-doors", null, true, "bundle,cell,tools");
                CodeDoors doors = new CodeDoors(rt, outside)) {
            doors.tryAll();
            String table = table(doors.attempts);
            System.out.println(String.join("\n", doors.controls) + "\n" + table);
            assertTrue(doors.attempts.size() >= 14, table);
            assertEquals(List.of(), doors.attempts.stream().filter(CodeDoors.Attempt::succeeded).toList(),
                    "doors that let unverified code run:\n" + table);
            for (CodeDoors.Attempt a : doors.attempts) {
                assertTrue(a.detail().contains("refused") || a.detail().contains("not ") || a.detail().contains("SHA-256"),
                        "a refusal says why: " + a.door() + ": " + a.detail());
            }
            // installed is not executed: the bundles Felix took are left unresolved
            assertTrue(doors.attempts.stream().filter(a -> a.door().startsWith("felix install"))
                    .allMatch(a -> a.detail().contains("bundle state 2 (INSTALLED")), table);
        }
    }

    /** A refused bundle left INSTALLED keeps no other bundle from resolving and starting. */
    @Test
    void aRefusedBundleLeftInstalledBlocksNothingElse() throws Exception {
        Path outside = Path.of(System.getProperty("arflex.it.work")).resolve("refused-left-attacker");
        try (Runtime rt = new Runtime("refused-left", null, true, "bundle,cell,tools");
                CodeDoors doors = new CodeDoors(rt, outside)) {
            String out = rt.cmd("install " + outside.resolve("evil.jar").toUri());
            long evil = Long.parseLong(out.replaceAll("(?s).*Bundle ID: (\\d+).*", "$1"));
            rt.cmd("start " + evil);
            Path scaler = java.nio.file.Files.copy(Components.jar("sample-scaler"),
                    rt.dir.resolve("tools/scaler.jar"));
            long ok = rt.installAndStart(scaler);
            assertEquals("32", rt.cmd("(bundle " + ok + ") state").strip(), "a trusted bundle still starts");
            assertEquals("2", rt.cmd("(bundle " + evil + ") state").strip(), "the refused one stays INSTALLED");
            rt.cmd("uninstall " + evil);
        }
    }

    /**
     * Finding 6: forged requests (SHUTDOWN made force-guard exit, STOP made it look hung, three
     * made it FAILED) are counted and ignored; a flooded queue does not lose the DRCR's own
     * command; names squatted before the install neither get adopted nor keep it from starting.
     */
    @Test
    void forgedRequestsAndSquattedNamesChangeNothing() throws Exception {
        try (Runtime rt = new Runtime("mailbox-doors", null, true, "bundle,cell,tools")) {
            Path jar = java.nio.file.Files.copy(Components.jar("sample-counter"),
                    java.nio.file.Files.createDirectories(rt.dir.resolve("tools")).resolve("counter.jar"));
            MailboxDoors mb = new MailboxDoors(rt);
            mb.trySquat(jar);
            long id = rt.installAndStart(jar);
            rt.awaitState("ACTIVE", CellIT.T, CodeDoors.COMPONENT);
            mb.tryForged();
            rt.cmd("uninstall " + id);
            String table = table(mb.attempts);
            System.out.println(table);
            assertEquals(6, mb.attempts.size(), table);
            assertEquals(List.of(), mb.attempts.stream().filter(CodeDoors.Attempt::succeeded).toList(), table);
            assertTrue(mb.attempts.stream().filter(a -> a.door().startsWith("forged"))
                    .allMatch(a -> a.detail().contains("all counted as forged")), table);
            assertTrue(rt.logContains("existed before this runtime created it"), "the squat is logged\n" + rt.tail());
        }
    }

    /**
     * Finding 5: a runtime started under umask 000 (not through scripts/run-cell.sh) leaves
     * nothing on the way to its code writable by others, and an executable replaced on disk is
     * not what runs at the next restart.
     */
    @Test
    void aRuntimeStartedUnderUmask000LeavesNoWritableCode() throws Exception {
        CodeDoors.Attempt a = CodeDoors.umask000(Path.of(System.getProperty("arflex.it.work")));
        assertFalse(a.succeeded(), a.detail());
        assertTrue(a.detail().contains("came back verified"), a.detail());
    }
}
