package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.file.Files;
import java.nio.file.Path;
import java.util.Map;
import java.util.regex.Matcher;
import java.util.regex.Pattern;
import org.junit.jupiter.api.Test;

/**
 * docs/DECISIONS.md D51 through the real runtime, on the moving arm of UpdateSetIT (two CPUs with
 * a cap of 1.0; tcp-correction, 100 us, shares its CPU with sim-robot, 300 us): a version of
 * tcp-correction that declares a WCET of 650 us fits that CPU alone (0.95), but not beside the
 * running version, neither in its shadow run (the old 0.1 and the new 0.65 beside sim-robot)
 * nor in its rollback window. The set is refused by its plan, in the dry run and in the apply,
 * naming the update, the phase, the CPU and the utilisation, and nothing is spawned: no
 * {@code 1-tcp-correction} process or segment, every pid and binding as before.
 */
class TransientAdmissionIT {

    static final long T = CellRig.T;

    @Test
    void anUpdateWhoseTwoHalvesDoNotFitTheirCpuIsRefusedByItsPlanWithNothingSpawned() throws Exception {
        CellRig.assertBuilt(CellRig.SIM_ROBOT, CellRig.TRAJECTORY, CellRig.FORCE_GUARD, CellRig.TCP_CORRECTION);
        try (Runtime rt = new Runtime("transient-admission")) {
            FailSafeIT.movingCell(rt);
            Path dir = Files.createDirectories(rt.dir.resolve("versions"));
            Path jar = ShadowRunIT.version(dir, CellRig.TCP_CORRECTION, "tcp-correction-1.0.1-heavy", UpdateSetIT.CONTRACT,
                    xml -> ShadowRunIT.versioned("tcp-correction", "1.0.1-heavy").apply(xml)
                            .replace("wcet=\"100us\"", "wcet=\"650us\""), null, null);
            Map<String, Long> before = ShadowRunIT.pids(rt);
            String bindings = rt.cmd("arflex:bindings");
            String version = rt.cmd("arflex:info tcp-correction").lines().findFirst().orElse("");
            String set = "update tcp-correction file:" + jar + " " + UpdateSetIT.sha256(jar) + " shadow 200";
            String dry = rt.cmd("arflex:change plan " + set);
            System.out.println("TransientAdmissionIT: dry run:\n" + dry);
            String apply = rt.cmd("arflex:change apply " + set);
            System.out.println("TransientAdmissionIT: apply:\n" + apply);
            Pattern refusal = Pattern.compile("\nrefused: update 'tcp-correction': its shadow run \\(200 cycles\\) runs "
                    + "the new half beside the old one: cpu (\\d+): utilisation ([0-9.]+) with 'tcp-correction \\(new\\)' "
                    + "exceeds cap 1.00; update 'tcp-correction': its rollback window \\(1000 cycles\\) keeps the old "
                    + "half running beside the new one: cpu (\\d+): utilisation ([0-9.]+) with 'tcp-correction \\(old\\)' "
                    + "exceeds cap 1.00\n");
            for (String out : new String[] {dry, apply}) {
                Matcher m = refusal.matcher(out);
                assertTrue(m.find(), out);
                assertEquals(m.group(1), m.group(3), "both halves on the running version's cpu");
                assertTrue(Double.parseDouble(m.group(2)) > 1.0, out);
                // the cell after the set fits: the new version alone beside sim-robot on that cpu
                assertTrue(out.contains("\n  cpu " + m.group(1) + "  U=0.95/1.00  "), out);
                assertTrue(out.contains("not schedulable while both halves run:"), out);
            }
            // nothing was spawned or created, nothing rebound
            assertTrue(Runtime.rtProcesses(rt.rid).stream().noneMatch(p -> p.contains("--instance 1-tcp-correction ")),
                    Runtime.rtProcesses(rt.rid)::toString);
            assertTrue(Files.list(Path.of("/dev/shm")).noneMatch(f -> f.getFileName().toString()
                    .startsWith("arflex." + rt.rid + ".1-tcp-correction.")));
            assertEquals(before, ShadowRunIT.pids(rt), "every half runs on with its pid");
            assertEquals(bindings, rt.cmd("arflex:bindings"));
            assertEquals(version, rt.cmd("arflex:info tcp-correction").lines().findFirst().orElse(""),
                    "the running version is the component's");
            assertTrue(CellRig.armFollows(rt, "trajectory"), rt.cmd("arflex:bindings"));
        }
    }
}
