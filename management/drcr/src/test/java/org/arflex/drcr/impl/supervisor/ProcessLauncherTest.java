package org.arflex.drcr.impl.supervisor;

import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.List;
import org.arflex.drcr.impl.abi.ControlBlock;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;

/** The launcher against real processes, shm and mq (no RT half: a shell script stands in). */
class ProcessLauncherTest {

    private final String rid = "pl" + ProcessHandle.current().pid();

    /**
     * An RT half that prints why it cannot start and exits at once: the launch fails with that
     * line in its reason, every time. The reason used to be built before the output pump had
     * read the pipe, so it sometimes lacked the line (a bad program file's {@code file:line} was
     * lost from the DRCR's failure reason: TeachIT failed in CI that way).
     */
    @Test
    void theReasonOfAFailedStartCarriesTheLastLineTheRtHalfPrinted(@TempDir Path dir) throws Exception {
        byte[] script = "#!/bin/sh\necho 'fails: bad program file: /data/program-3.arp:3: joint 6 outside' >&2\nexit 4\n"
                .getBytes(java.nio.charset.StandardCharsets.UTF_8);
        VerifiedExecutables exes = new VerifiedExecutables(dir, line -> { });
        Path exe = exes.extract(dir.resolve("native"), "fails", () -> new java.io.ByteArrayInputStream(script));
        ProcessLauncher launcher = new ProcessLauncher(line -> { }, exes);
        for (int i = 0; i < 30; i++) {
            String inst = "fails" + i;
            RtLauncher.Spec spec = new RtLauncher.Spec(rid, inst, exe,
                    new ControlBlock.Config(1_000_000, 1_000_000, 0, 0, 0, 0, 0, 0), List.of(), false, 5_000);
            IOException e = assertThrows(IOException.class, () -> launcher.launch(spec));
            assertTrue(e.getMessage().contains("exited with status 4"), e.getMessage());
            assertTrue(e.getMessage().contains("program-3.arp:3: joint 6"), "launch " + i + ": " + e.getMessage());
            for (String ch : List.of("ctl", "cmd", "rsp")) {
                String name = ProcessLauncher.objectName(rid, inst, ch);
                assertFalse(Files.exists(Path.of("/dev/shm" + name)) || Files.exists(Path.of("/dev/mqueue" + name)),
                        name + " left behind");
            }
        }
    }
}
