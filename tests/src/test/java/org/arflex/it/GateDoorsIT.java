package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.file.Path;
import java.util.List;
import java.util.stream.Collectors;
import org.junit.jupiter.api.Test;

/**
 * Issue 30 findings 1 and 10 against the real runtime (D78): a zip bomb through
 * {@code arflex:deploy} and through {@code install} + {@code start} is refused within
 * {@link GateDoors#QUICK_MS}, naming the limit, while the witness counter keeps running out of
 * safe mode; a trusted-signed jar with an unsigned signature-like file is not installed.
 */
class GateDoorsIT {

    @Test
    void bombsAreRefusedQuicklyAndSignatureLikeFilesAddedAfterSigningAreRefused() throws Exception {
        Path outside = Path.of(System.getProperty("arflex.it.work")).resolve("gate-doors-attacker");
        try (Runtime rt = new Runtime("gate-doors", null, true, "bundle,cell,tools")) {
            GateDoors doors = new GateDoors(rt, outside);
            doors.tryAll();
            String table = doors.attempts.stream().map(a -> (a.succeeded() ? "OPEN " : "shut ") + a.door() + ": "
                    + a.detail()).collect(Collectors.joining("\n"));
            System.out.println(String.join("\n", doors.controls) + "\n" + table);
            assertEquals(5, doors.attempts.size(), table);
            assertEquals(List.of(), doors.attempts.stream().filter(CodeDoors.Attempt::succeeded).toList(),
                    "doors open:\n" + table);
            for (CodeDoors.Attempt a : doors.attempts) {
                assertTrue(a.door().contains("bomb") ? a.detail().contains("limit") && a.detail().contains("bomb-0")
                        : a.detail().contains("EVIL"), "a refusal says why: " + a.door() + ": " + a.detail());
            }
        }
    }
}
