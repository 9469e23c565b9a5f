package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertNotEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.file.Files;
import java.nio.file.Path;
import java.util.List;
import java.util.Map;
import org.junit.jupiter.api.Test;

/** Continuous deployment from a file URL: right hash, wrong hash, broken jar. */
class UpdateIT {

    static final String UPDATE_AFTER = "<criticality>3</criticality>";

    private static Path v1(Path dir, Path target, String sha) throws Exception {
        return Jars.withContract(CellIT.SCALER, dir.resolve("scaler-v1.jar"), xml -> xml.replace(UPDATE_AFTER,
                UPDATE_AFTER + "<update url=\"" + target.toUri() + "\" sha256=\"" + sha + "\"/>"));
    }

    @SuppressWarnings("unchecked")
    private static String version(Runtime rt) {
        return Runtime.list(rt.dto(), "contracts").stream().filter(c -> "sample-scaler".equals(c.get("name")))
                .map(c -> (String) c.get("version")).findFirst().orElse(null);
    }

    @Test
    void updateWithTheRightHashRestartsOnlyTheUpdatedComponent() throws Exception {
        Path dir = Files.createTempDirectory("arflex-upd");
        Path v2 = Jars.withContract(CellIT.SCALER, dir.resolve("scaler-v2.jar"),
                xml -> xml.replace("version=\"1.0.0\"", "version=\"1.1.0\""));
        Path v1 = v1(dir, v2, Jars.sha256(v2));
        try (Runtime rt = new Runtime("update-ok")) {
            rt.installAndStart(CellIT.COUNTER);
            rt.installAndStart(v1);
            rt.awaitState("ACTIVE", CellIT.T, "sample-counter", "sample-scaler");
            long counterPid = rt.pid("sample-counter");
            long scalerPid = rt.pid("sample-scaler");
            String plan = rt.cmd("arflex:plan update sample-scaler");
            assertTrue(plan.lines().anyMatch(l -> l.contains("RESTART") && l.contains("sample-scaler")), plan);
            assertTrue(plan.lines().noneMatch(l -> l.contains("sample-counter") && (l.contains("RESTART") || l.contains("STOP"))), plan);
            assertEquals("1.0.0", version(rt), "a dry run installs nothing");
            String r = rt.cmd("arflex:update sample-scaler");
            assertTrue(r.contains("updated to 1.1.0"), r + "\n" + rt.tail());
            rt.awaitState("ACTIVE", CellIT.T, "sample-scaler");
            assertEquals("1.1.0", version(rt));
            assertNotEquals(scalerPid, rt.pid("sample-scaler"));
            assertEquals(counterPid, rt.pid("sample-counter"), "the provider must not restart");
            CellIT.assertDataFlows(rt, 2.0);
        }
    }

    @Test
    void wrongHashOrBrokenJarKeepsTheOldVersionRunning() throws Exception {
        Path dir = Files.createTempDirectory("arflex-upd");
        Path v2 = Jars.withContract(CellIT.SCALER, dir.resolve("scaler-v2.jar"),
                xml -> xml.replace("version=\"1.0.0\"", "version=\"1.1.0\""));
        Path broken = dir.resolve("broken.jar");
        Files.write(broken, "this is not a jar".getBytes());
        String wrong = "0".repeat(64);
        Path v1Wrong = v1(dir, v2, wrong);
        try (Runtime rt = new Runtime("update-bad")) {
            rt.installAndStart(CellIT.COUNTER);
            long bundle = rt.installAndStart(v1Wrong);
            rt.awaitState("ACTIVE", CellIT.T, "sample-counter", "sample-scaler");
            long scalerPid = rt.pid("sample-scaler");
            String r = rt.cmd("arflex:update sample-scaler");
            assertTrue(r.startsWith("error:") && r.contains("SHA-256") && r.contains("old version keeps running"), r);
            assertTrue(rt.cmd("arflex:plan update sample-scaler").startsWith("error:"), "the dry run checks the hash too");
            assertEquals("1.0.0", version(rt));
            assertEquals(scalerPid, rt.pid("sample-scaler"));
            // now a contract that pins the broken jar's own hash
            assertEquals("", rt.cmd("uninstall " + bundle));
            Path v1Broken = Jars.withContract(CellIT.SCALER, dir.resolve("scaler-v1b.jar"), xml -> xml.replace(
                    UpdateIT.UPDATE_AFTER, UpdateIT.UPDATE_AFTER + "<update url=\"" + broken.toUri() + "\" sha256=\""
                            + sha(broken) + "\"/>"));
            rt.installAndStart(v1Broken);
            rt.awaitState("ACTIVE", CellIT.T, "sample-scaler");
            long pid2 = rt.pid("sample-scaler");
            String r2 = rt.cmd("arflex:update sample-scaler");
            assertTrue(r2.startsWith("error:") && r2.contains("broken"), r2);
            assertEquals(pid2, rt.pid("sample-scaler"));
            assertEquals("ACTIVE", rt.state("sample-scaler"));
            Map<String, Object> dto = rt.dto();
            assertEquals(2, ((List<?>) dto.get("instances")).size());
        }
    }

    private static String sha(Path p) {
        try {
            return Jars.sha256(p);
        } catch (Exception e) {
            throw new IllegalStateException(e);
        }
    }
}
