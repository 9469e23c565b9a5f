package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertNotEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import java.util.function.UnaryOperator;
import org.junit.jupiter.api.Test;

/**
 * docs/DECISIONS.md D52 through the real runtime: force-guard's latched protective stop survives
 * an update in a change set (fail closed, shared/SAFETY.md). A 400 N push on the arm
 * ({@code arflex:set sim-robot push_force_n 400}) latches the guard; with the push over and the
 * stop still latched, force-guard is updated to 1.0.1 (the built bundle under a new contract
 * version, pinned). The new half adopts the old half's state block (arflex.ForceGuardState):
 * its first safety value and every one after it is the protective stop with the old cause and
 * RESET_REQUIRED, the cell still awaits the operator's reset, and only that reset releases it.
 * Without the state block a new half would have started NORMAL (cell.force_guard_state shows
 * it under the host API).
 */
class ForceGuardUpdateIT {

    static final long T = CellRig.T;
    static final String CONTRACT = "OSGI-INF/arflex/force-guard.xml";
    static final int FORCE_LIMIT = 0x1;
    static final int RESET_REQUIRED = 0x4;

    static Path version(Path dir, String version) throws IOException {
        Map<String, UnaryOperator<byte[]>> edits = new LinkedHashMap<>();
        edits.put(CONTRACT, BundleCopies.text(xml -> {
            assertTrue(xml.contains("<state type=\"arflex.ForceGuardState\""), "the built force-guard declares its state");
            return xml.replaceFirst("name=\"force-guard\" version=\"[^\"]+\"", "name=\"force-guard\" version=\"" + version + "\"");
        }, "the contract's version attribute"));
        edits.put("META-INF/MANIFEST.MF", BundleCopies.text(mf -> mf.replaceFirst("Bundle-Version: [^\r\n]+",
                "Bundle-Version: " + version), "the manifest's Bundle-Version"));
        return BundleCopies.copy(dir, CellRig.FORCE_GUARD, "force-guard-" + version, edits);
    }

    /** The newest safety value of the half running under {@code id}. */
    static CellRig.Safety safety(Runtime rt, String id) {
        try (CellRig.Port p = new CellRig.Port(rt.segment(id, "safety"), CellRig.SAFETY_SIZE)) {
            return CellRig.Safety.of(p.read());
        } catch (IOException e) {
            return null;
        }
    }

    static boolean stopped(CellRig.Safety s) {
        return s != null && s.mode() == CellRig.Safety.PROTECTIVE_STOP && (s.flags() & RESET_REQUIRED) != 0;
    }

    @Test
    void aLatchedStopSurvivesAnUpdateOfTheGuard() throws Exception {
        CellRig.assertBuilt(CellRig.SIM_ROBOT, CellRig.FORCE_GUARD);
        try (Runtime rt = new Runtime("forceguard-update")) {
            CellRig.installArm(rt);
            rt.awaitState("ACTIVE", T, "sim-robot", "force-guard");
            CellRig.resetBeforeTheTest(rt, "ForceGuardUpdateIT");
            rt.waitUntil("the guard NORMAL", T, () -> {
                CellRig.Safety s = safety(rt, "force-guard");
                return s != null && s.mode() == CellRig.Safety.NORMAL;
            });
            // the push: latched
            CellRig.set(rt, "sim-robot", "push_duration_ms", "200");
            CellRig.set(rt, "sim-robot", "push_force_n", "400");
            rt.waitUntil("the guard's protective stop", T, () -> stopped(safety(rt, "force-guard")));
            rt.waitUntil("the push over, the stop latched", T, () -> {
                CellRig.Safety s = safety(rt, "force-guard");
                return stopped(s) && s.forceNorm() < s.forceLimit();
            });
            assertTrue(CellRig.awaitingReset(rt).contains("force-guard"), CellRig.awaitingReset(rt).toString());
            CellRig.Safety old = safety(rt, "force-guard");
            long oldPid = rt.pid("force-guard");

            // the update, while latched
            Path jar = version(Files.createDirectories(rt.dir.resolve("versions")), "1.0.1");
            int logMark = rt.logMark();
            String out = rt.cmd("arflex:change apply update force-guard file:" + jar + " " + UpdateSetIT.sha256(jar)
                    + " window 300");
            List<String> log = rt.logSince(logMark);
            System.out.println("ForceGuardUpdateIT: apply:\n" + out);
            assertTrue(out.contains("update force-guard: committed"), out + "\n" + String.join("\n", log));
            assertTrue(log.stream().anyMatch(l -> l.contains("1-force-guard") && l.contains(
                    "adopted the state block arflex.ForceGuardState 1.0 of /arflex." + rt.rid + ".force-guard.state")),
                    "the new half's adoption in the log:\n" + String.join("\n", log));
            rt.awaitState("ACTIVE", T, "force-guard", "sim-robot");
            assertNotEquals(oldPid, rt.pid("force-guard"), "the new version runs");
            CellRig.Safety first = safety(rt, "1-force-guard");
            System.out.println("ForceGuardUpdateIT: the old half's last safety value " + old + "; the new half's " + first);
            assertTrue(stopped(first) && (first.flags() & FORCE_LIMIT) != 0, "the new half's safety value: " + first);
            assertTrue(first.seq() > old.seq(), "its seq continues the old half's: " + first + " after " + old);
            assertTrue(CellRig.awaitingReset(rt).contains("force-guard"), "awaiting reset after the update: "
                    + CellRig.awaitingReset(rt));
            // it stays latched: 500 more values, every one seen a stop
            long until = first.seq() + 500;
            rt.waitUntil("500 safety values of the new half, each a stop", T, () -> {
                CellRig.Safety s = safety(rt, "1-force-guard");
                assertTrue(stopped(s), "the new half left the stop without a reset: " + s);
                return s.seq() > until;
            });
            String r = rt.cmd("arflex:reset force-guard");
            assertTrue(r.startsWith("force-guard: reset"), r);
            rt.waitUntil("NORMAL after the operator's reset", T, () -> {
                CellRig.Safety s = safety(rt, "1-force-guard");
                return s != null && s.mode() == CellRig.Safety.NORMAL;
            });
            assertTrue(rt.cmd("arflex:info force-guard").startsWith("force-guard 1.0.1 "), rt.cmd("arflex:info force-guard"));
            assertEquals(0, ((Number) rt.instance("force-guard").get("restarts")).intValue());
            rt.waitUntil("the old half and its segments gone", T, () -> Runtime.rtProcesses(rt.rid).stream()
                    .noneMatch(p -> p.contains("--instance force-guard ")) && !Files.exists(rt.segment("force-guard", "safety")));
        }
    }
}
