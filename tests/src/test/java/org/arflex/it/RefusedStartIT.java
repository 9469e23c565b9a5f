package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.file.Files;
import java.nio.file.Path;
import java.util.List;
import java.util.Locale;
import org.junit.jupiter.api.Test;

/**
 * docs/DECISIONS.md D55 through the real runtime (D58): on the moving arm of UpdateSetIT
 * (trajectory -> tcp-correction -> sim-robot, the guard watching), tcp-correction is updated in a
 * change set to 1.0.3-refuses-start, a pinned copy of the built bundle whose executable is a
 * script that runs the real one with rt-core's test fault {@code ARFLEX_FAULT_START_ERRNO=125}:
 * the new half comes up READY beside the old one, takes its BINDs and the old half's state block
 * (ADOPT), and refuses its START in the switch turn. The switch hands the component back to the
 * old half, which never stopped and which sim-robot never stopped reading: the change set
 * reports {@code rolled back at the switch: its START was refused (...)}, the old pid runs it with
 * no restart, nothing awaits a reset, sim-robot runs no safe cycle and the guard stays NORMAL
 * (UpdateSetIT.update's checks), no consumer is rewired, and nothing of the refused half is left:
 * no process, no segment (its outputs and its state block) and no message queue.
 */
class RefusedStartIT {

    static final long T = CellRig.T;
    /** ECANCELED: what the faulty version's half answers its START with. */
    static final int REFUSED_WITH = 125;

    @Test
    void anUpdateWhoseNewHalfRefusesItsStartIsHandedBackToTheRunningHalf() throws Exception {
        CellRig.assertBuilt(CellRig.SIM_ROBOT, CellRig.TRAJECTORY, CellRig.FORCE_GUARD, CellRig.TCP_CORRECTION);
        try (Runtime rt = new Runtime("update-refused")) {
            FailSafeIT.movingCell(rt);
            Path dir = Files.createDirectories(rt.dir.resolve("versions"));
            Path jar = UpdateSetIT.version(dir, "1.0.3-refuses-start", FaultyVersions.refusingStart(dir,
                    CellRig.TCP_CORRECTION, UpdateSetIT.EXE, REFUSED_WITH, "RefusedStartIT"));
            long oldPid = rt.pid("tcp-correction");
            String versionBefore = rt.cmd("arflex:info tcp-correction").lines().findFirst().orElse("");
            int mark = rt.logMark();

            UpdateSetIT.Run r = UpdateSetIT.update(rt, jar, "window 1000");
            List<String> log = rt.logSince(mark);
            System.out.println("RefusedStartIT: the runtime's log since the apply:\n" + String.join("\n", log.stream()
                    .filter(l -> (l.contains("tcp-correction") || l.contains("rewired")) && !l.contains("{")).toList()));
            String verdict = r.out().lines().filter(l -> l.contains("update tcp-correction:")).findFirst().orElse("");
            System.out.printf(Locale.ROOT, "RefusedStartIT: %s (command %d ms)%n", verdict, r.applyMs());
            assertTrue(verdict.startsWith("update tcp-correction: rolled back at the switch: its START was refused (")
                    && verdict.contains("START refused by 1-tcp-correction: status -" + REFUSED_WITH)
                    && verdict.endsWith("pid " + oldPid + " (tcp-correction) runs it again"), r.out());
            // the half refused for the reason the fault gives, after taking the old half's state block
            assertTrue(log.stream().anyMatch(l -> l.contains("START refused: test fault ARFLEX_FAULT_START_ERRNO="
                    + REFUSED_WITH)), "the new half's refusal in the log");

            // the old version runs on, bound, and is the component again
            assertEquals(oldPid, r.oldPid());
            assertEquals(oldPid, rt.pid("tcp-correction"), "the old half runs the component");
            assertEquals(0, ((Number) rt.instance("tcp-correction").get("restarts")).intValue(), "no restart");
            rt.awaitState("ACTIVE", T, "tcp-correction", "sim-robot", "force-guard", "trajectory");
            assertEquals(versionBefore, rt.cmd("arflex:info tcp-correction").lines().findFirst().orElse(""),
                    "the running contract is the old one");
            assertTrue(CellRig.armFollows(rt, "trajectory"), rt.cmd("arflex:bindings"));
            assertTrue(log.stream().noneMatch(l -> l.contains(" rewired by ")),
                    "no consumer was rebound: " + log.stream().filter(l -> l.contains(" rewired by ")).toList());
            assertTrue(rt.cmd("arflex:list").contains("rolled back at the switch"), rt.cmd("arflex:list"));
            assertEquals(0, r.robotSafe(), "sim-robot ran safe cycles");
            assertEquals(List.of(), CellRig.awaitingReset(rt));
            // the refused half wrote nothing a consumer could have read
            assertEquals(0.0, r.jump(), "no value of the refused version was seen");

            // nothing of the refused half is left: process, segments, state block, queues
            rt.waitUntil("no process, segment or queue of 1-tcp-correction", T, () -> Runtime.rtProcesses(rt.rid)
                    .stream().noneMatch(p -> p.contains("--instance 1-tcp-correction "))
                    && DeploymentSetIT.objects(rt, "1-tcp-correction").isEmpty());
            for (String ch : new String[] {"cmd", "rsp"}) {
                int d = Runtime.LibC.C.mq_open("/arflex." + rt.rid + ".1-tcp-correction." + ch, 0);
                if (d >= 0) {
                    Runtime.LibC.C.mq_close(d);
                }
                assertTrue(d < 0, "the queue /arflex." + rt.rid + ".1-tcp-correction." + ch + " is left");
            }
            // the component takes a good update afterwards (the set's window is closed, nothing blocked)
            String next = rt.cmd("arflex:change plan update tcp-correction file:" + UpdateSetIT.version(dir, "1.0.1", null)
                    + " " + UpdateSetIT.sha256(dir.resolve("tcp-correction-1.0.1.jar")));
            assertTrue(next.contains("admitted (dry run: nothing changed)"), next);
        }
    }
}
