package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.file.Path;
import java.util.List;
import java.util.stream.Collectors;
import org.junit.jupiter.api.Test;

/**
 * Issue 16 finding 3 against the real runtime: no way of bringing code in through Felix's own
 * shell, a manifest header or our commands gets an RT half running unless the jar was pinned
 * or comes from the runtime's own folders. The runtime trusts only its defaults
 * ({@code bundle,cell,tools}); the attacker's jars lie in the build folder, outside them.
 * Before the code gate every Felix door here started the counter's RT half.
 */
class CodeDoorsIT {

    @Test
    void everyUnverifiedDoorIsShutAndSaysWhy() throws Exception {
        Path outside = Path.of(System.getProperty("arflex.it.work")).resolve("code-doors-attacker");
        try (Runtime rt = new Runtime("code-doors", null, true, "bundle,cell,tools");
                CodeDoors doors = new CodeDoors(rt, outside)) {
            doors.tryAll();
            List<CodeDoors.Attempt> open = doors.attempts.stream().filter(CodeDoors.Attempt::succeeded).toList();
            String table = doors.attempts.stream().map(a -> (a.succeeded() ? "OPEN " : "shut ") + a.door() + ": " + a.detail())
                    .collect(Collectors.joining("\n"));
            System.out.println(String.join("\n", doors.controls) + "\n" + table);
            assertTrue(doors.attempts.size() >= 14, table);
            assertEquals(List.of(), open, "doors that let unverified code run:\n" + table);
            // Each refusal says why: the gate's reason or the transport's.
            for (CodeDoors.Attempt a : doors.attempts) {
                assertTrue(a.detail().contains("refused") || a.detail().contains("not ") || a.detail().contains("SHA-256"),
                        a.door() + ": " + a.detail());
            }
        }
    }
}
