package org.arflex.drcr.impl.runtime;

import static org.arflex.drcr.impl.runtime.UpdateRig.IN_SRC;
import static org.arflex.drcr.impl.runtime.UpdateRig.OUT;
import static org.arflex.drcr.impl.runtime.UpdateRig.parse;
import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.file.Path;
import java.util.List;
import java.util.Map;
import java.util.concurrent.CompletableFuture;
import java.util.concurrent.ExecutorService;
import java.util.concurrent.Executors;
import org.arflex.contract.Contract;
import org.arflex.drcr.dto.ChangeSetDTO;
import org.arflex.drcr.dto.UpdateProgressDTO;
import org.arflex.drcr.impl.services.ChangeSets;
import org.junit.jupiter.api.AfterEach;
import org.junit.jupiter.api.Test;

/**
 * The history of applied sets keeps each update's entry (D62): a set of two updates applied
 * through the {@link ChangeSets} service on the stepped cell of {@link ChangeSetProgressTest},
 * one of them rejected in shadow, the other's shadow run cancelled for it; the service's history
 * record says so for each, with its counters, as the progress showed them.
 */
class ChangeSetHistoryEntriesTest {

    private final UpdateRig rig = new UpdateRig();
    private final FakeLauncher fake = rig.fake;
    private final ExecutorService caller = Executors.newSingleThreadExecutor(r -> new Thread(r, "apply caller"));

    @AfterEach
    void nothingLeaks() {
        caller.shutdownNow();
        rig.close();
    }

    @Test
    void aSetRejectedInShadowIsRecordedWithEachUpdatesEntryTheOtherCancelled() throws Exception {
        rig.runningCell("50us", "");
        Map<String, Contract> next = Map.of("src", parse("src", "src", OUT, "1.1.0"),
                "stage", parse("stage", "stage", IN_SRC + OUT, "1.1.0"));
        ChangeSets service = new ChangeSets(rig.cell, null, rig.log::add);
        service.versions((component, location, sha256) -> new ChangeSets.Version(next.get(component), location,
                "a test's double", () -> Path.of("/nonexistent/" + component + "-1.1"), new byte[0]));
        Thread[] applying = new Thread[1];
        // the service's caller (the shell's or the console's thread); its calls to the actor run
        // inline on the stepped actor, so the test steps only once it waits for the outcome
        CompletableFuture<ChangeSetDTO> f = CompletableFuture.supplyAsync(() -> {
            applying[0] = Thread.currentThread();
            return service.apply(List.of("update src file:/x/src-1.1.jar shadow 100 window 40 tolerance y.value 0.01",
                    "update stage file:/x/stage-1.1.jar shadow 200 window 50 tolerance y.value 0.01"));
        }, caller);
        // not stepped meanwhile: the caller's calls run on the stepped actor as if on its thread
        long deadline = System.nanoTime() + java.util.concurrent.TimeUnit.SECONDS.toNanos(10);
        while (!(f.isDone() || applying[0] != null && applying[0].getState() == Thread.State.TIMED_WAITING
                && rig.cell.changeSetProgress().snapshot() != null
                && rig.cell.changeSetProgress().snapshot().updates.length == 2)) {
            assertTrue(System.nanoTime() - deadline < 0, "timed out waiting for the caller to wait for the outcome: "
                    + rig.log);
            java.util.concurrent.locks.LockSupport.parkNanos(1_000_000);
        }
        rig.stepUntil("both new halves started in shadow", () -> fake.events.contains("1-src START")
                && fake.events.contains("1-stage START") || f.isDone());
        assertTrue(!f.isDone(), () -> "the set ended before its shadow runs: " + f.join().text + "\n" + rig.log);
        FakeLauncher.FakeHalf newSrc = fake.running.get("1-src");
        FakeLauncher.FakeHalf newStage = fake.running.get("1-stage");
        newSrc.stats = UpdateRig.cycles(25, 0);
        newStage.stats = UpdateRig.cycles(45, 0);
        rig.look();
        newStage.crash(139, "killed by signal 11");
        rig.stepUntil("the service's answer", f::isDone);
        ChangeSetDTO answer = f.join();
        assertEquals("rejected-in-shadow", answer.outcome, answer.text);

        List<ChangeSetDTO> history = service.history();
        assertEquals(1, history.size());
        ChangeSetDTO h = history.get(0);
        assertEquals("rejected-in-shadow", h.outcome);
        assertEquals(2, h.updates.length, "an entry per update, in the set's order");
        UpdateProgressDTO src = h.updates[0];
        UpdateProgressDTO stage = h.updates[1];
        assertEquals(java.util.Arrays.asList("src", "shadow", 25L, 100L, "cancelled"),
                java.util.Arrays.asList(src.component, src.phase, src.cycle, src.cycles, src.verdict));
        assertEquals("cancelled: update stage was rejected in shadow (the new version (pid " + newStage.pid
                + ") exited: killed by signal 11)", src.why);
        assertEquals(java.util.Arrays.asList("stage", "shadow", 45L, 200L, "rejected-in-shadow"),
                java.util.Arrays.asList(stage.component, stage.phase, stage.cycle, stage.cycles, stage.verdict));
        assertEquals(h.refusal, stage.why);
        assertEquals("y.value", src.worstField);
        assertEquals(0.01, src.tolerance);
        // the same as the progress's last snapshot, and a reader's change is not kept
        UpdateProgressDTO[] shown = rig.cell.changeSetProgress().snapshot().updates;
        assertEquals(shown[0].why, src.why);
        assertEquals(shown[1].cycle, stage.cycle);
        h.updates[0].verdict = "changed by a reader";
        assertEquals("cancelled", service.history().get(0).updates[0].verdict);
        assertTrue(fake.running.containsKey("src") && fake.running.containsKey("stage"), "the old versions run on");
    }
}
