package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;

import java.nio.file.Files;
import java.nio.file.Path;
import java.util.List;
import java.util.stream.Collectors;
import org.junit.jupiter.api.AfterEach;
import org.junit.jupiter.api.BeforeEach;
import org.junit.jupiter.api.Test;

/**
 * Issue 30 findings 2, 3 and 4 end to end (docs/decisions/D79): a second local user, created for
 * each test and removed after it, plants names in /dev/shm; the runtime starts, stops, keeps its
 * id and restarts its component as if they were not there.
 */
class ShmDoorsIT {

    private ShmDoors doors;

    @BeforeEach
    void attacker() throws Exception {
        doors = new ShmDoors();
    }

    @AfterEach
    void removeAttacker() throws Exception {
        doors.close();
    }

    private void assertAllShut() {
        String table = doors.attempts.stream().map(a -> (a.succeeded() ? "OPEN " : "shut ") + a.door() + ": " + a.detail())
                .collect(Collectors.joining("\n"));
        System.out.println(table);
        assertEquals(List.of(), doors.attempts.stream().filter(CodeDoors.Attempt::succeeded).toList(), table);
    }

    /** Finding 2: the sweep opened the FIFO and blocked: no DRCR, and a stop 0 that hung. */
    @Test
    void aFifoInDevShmBlocksNeitherStartNorStop() throws Exception {
        doors.tryFifo();
        assertEquals(2, doors.attempts.size(), doors.attempts.toString());
        assertAllShut();
    }

    /** Finding 3: a forged control block made the DRCR refuse its start, or got the named pid killed as root. */
    @Test
    void aForgedControlBlockNeitherStopsTheDrcrNorGetsAProcessKilled() throws Exception {
        doors.tryForgedControlBlock(true);
        doors.tryForgedControlBlock(false);
        assertAllShut();
    }

    /** Finding 4: a directory at a stopped or crashed component's name made its restarts fail until FAILED. */
    @Test
    void aSquattedDirectoryDoesNotKeepAComponentFromStarting() throws Exception {
        try (Runtime rt = new Runtime("shm-squat", null, true, "bundle,cell,tools")) {
            Path jar = Files.copy(Components.jar("sample-counter"),
                    Files.createDirectories(rt.dir.resolve("tools")).resolve("counter.jar"));
            long id = rt.installAndStart(jar);
            rt.awaitState("ACTIVE", CellIT.T, CodeDoors.COMPONENT);
            doors.trySquattedDirectory(rt, id);
            assertAllShut();
            rt.dto(); // record the instance for the queue leak check
            rt.cmd("uninstall " + id);
            rt.waitUntil(CodeDoors.COMPONENT + " gone", CellIT.T, () -> rt.instance(CodeDoors.COMPONENT) == null);
        }
        assertEquals(2, doors.attempts.size(), doors.attempts.toString());
    }
}
