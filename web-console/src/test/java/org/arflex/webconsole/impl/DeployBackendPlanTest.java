package org.arflex.webconsole.impl;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.io.InputStream;
import java.io.OutputStream;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.Map;
import java.util.Optional;
import java.util.function.Function;
import java.util.jar.Attributes;
import java.util.jar.JarOutputStream;
import java.util.jar.Manifest;
import org.arflex.drcr.DrcrService;
import org.arflex.drcr.dto.CellDTO;
import org.arflex.drcr.dto.ContractDTO;
import org.arflex.drcr.dto.InstanceDTO;
import org.junit.jupiter.api.BeforeEach;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;

/**
 * The Deploy page's dry runs: a plan the DRCR could not make is an error naming why, never a
 * plan text that could be confirmed (update and staged installs alike).
 */
class DeployBackendPlanTest {
    @TempDir
    Path dir;

    private final Backend backend = new Backend();
    private DeployBackend deploy;
    private final List<String> updated = new ArrayList<>();
    private ContractDTO scaler;
    private Function<String, String> planUpdate;
    private Function<String, String> planInstall;

    @BeforeEach
    void setUp() {
        scaler = new ContractDTO();
        scaler.name = "sample-scaler";
        scaler.version = "1.0.0";
        scaler.updateUrl = "file:/tmp/scaler-v2.jar";
        scaler.updateSha256 = "ab".repeat(32);
        deploy = new DeployBackend(backend, new StagingArea(backend, dir.resolve("staging")), dir.resolve("installed"),
                StagingSources.parse(null));
        backend.drcr = new DrcrService() {
            @Override
            public CellDTO cell() {
                return new CellDTO();
            }

            @Override
            public Optional<InstanceDTO> instance(String name) {
                return Optional.empty();
            }

            @Override
            public Optional<ContractDTO> contract(String name) {
                return name.equals(scaler.name) ? Optional.of(scaler) : Optional.empty();
            }

            @Override
            public String planInstall(String location) {
                return planInstall.apply(location);
            }

            @Override
            public String planUpdate(String name) {
                return planUpdate.apply(name);
            }

            @Override
            public String planUninstall(String name) {
                return "plan: uninstall " + name;
            }

            @Override
            public String planCapacity(List<Integer> cpus, long memoryBytes, long networkBps) {
                return "plan: capacity";
            }
        };
        backend.updates = new org.arflex.drcr.UpdateService() {
            @Override
            public String update(String name) {
                updated.add(name);
                return name + ": updated to 1.1.0";
            }

            @Override
            public void verified(byte[] jar, String sha256, String origin) {
                updated.add("verified " + origin);
            }
        };
    }

    @Test
    void anUpdatePlanCarriesTheDrcrTextAndThePinItWasMadeFor() throws Exception {
        planUpdate = n -> "update of " + n + " from file:/tmp/scaler-v2.jar (sha256 verified)\nactions:\n  RESTART  " + n;
        Map<String, Object> m = deploy.planUpdate("sample-scaler");
        assertEquals("sample-scaler", m.get("component"));
        assertEquals("1.0.0", m.get("version"));
        assertEquals(scaler.updateUrl, m.get("updateUrl"));
        assertEquals(scaler.updateSha256, m.get("sha256"));
        assertTrue(((String) m.get("plan")).contains("RESTART  sample-scaler"), (String) m.get("plan"));
        assertTrue(updated.isEmpty(), "a plan updates nothing");
    }

    @Test
    void anUpdateThatCannotBePlannedIsAnErrorNamingWhy() {
        planUpdate = n -> {
            throw new IllegalStateException(n + ": its contract has no update URL");
        };
        HttpError e = assertThrows(HttpError.class, () -> deploy.planUpdate("sample-scaler"));
        assertEquals(409, e.status);
        assertEquals("cannot plan the update of sample-scaler: its contract has no update URL", e.getMessage());

        planUpdate = n -> {
            throw new IllegalStateException(n + ": update not installed, the old version keeps running: SHA-256 of"
                    + " file:/tmp/scaler-v2.jar is 00, the contract pins ab");
        };
        e = assertThrows(HttpError.class, () -> deploy.planUpdate("sample-scaler"));
        assertEquals(409, e.status);
        assertTrue(e.getMessage().startsWith("cannot plan the update of sample-scaler: update not installed")
                && e.getMessage().contains("SHA-256"), e.getMessage());

        planUpdate = n -> {
            throw new NullPointerException();
        };
        e = assertThrows(HttpError.class, () -> deploy.planUpdate("sample-scaler"));
        assertEquals("cannot plan the update of sample-scaler: NullPointerException", e.getMessage());

        e = assertThrows(HttpError.class, () -> deploy.planUpdate("nope"));
        assertEquals(404, e.status);
        assertTrue(e.getMessage().contains("no component named 'nope'"), e.getMessage());
        assertEquals(400, assertThrows(HttpError.class, () -> deploy.planUpdate("<b>")).status);
        assertTrue(updated.isEmpty());
    }

    @Test
    void anUpdateIsRefusedWhenTheContractPinsSomethingElseThanThePlanShown() throws Exception {
        HttpError e = assertThrows(HttpError.class, () -> deploy.update("sample-scaler", "cd".repeat(32)));
        assertEquals(409, e.status);
        assertTrue(e.getMessage().contains("plan the update again") && e.getMessage().contains(scaler.updateSha256),
                e.getMessage());
        assertTrue(updated.isEmpty());
        assertEquals("sample-scaler: updated to 1.1.0",
                deploy.update("sample-scaler", scaler.updateSha256.toUpperCase()).get("report"));
        assertEquals(List.of("sample-scaler"), updated);
    }

    private InputStream bundle(String bsn) throws IOException {
        Manifest m = new Manifest();
        m.getMainAttributes().put(Attributes.Name.MANIFEST_VERSION, "1.0");
        m.getMainAttributes().putValue("Bundle-SymbolicName", bsn);
        m.getMainAttributes().putValue("Bundle-Version", "1.0.0");
        Path p = dir.resolve(bsn + ".jar");
        try (OutputStream out = new JarOutputStream(Files.newOutputStream(p), m)) {
            out.flush();
        }
        return Files.newInputStream(p);
    }

    private long staged() throws IOException {
        return ArtifactsTest.stagedFiles(dir);
    }

    @Test
    void aStagedInstallThatCannotBePlannedIsNotStagedAndNotConfirmable() throws Exception {
        planInstall = loc -> {
            throw new IllegalStateException("actor did not answer within 5000 ms");
        };
        HttpError e;
        try (InputStream in = bundle("org.example.unplannable")) {
            e = assertThrows(HttpError.class, () -> deploy.stageUpload(in, "unplannable.jar"));
        }
        assertEquals(409, e.status);
        assertTrue(e.getMessage().startsWith("the DRCR could not plan the install of org.example.unplannable 1.0.0")
                && e.getMessage().endsWith("nothing staged: actor did not answer within 5000 ms"), e.getMessage());
        assertEquals(0, staged(), "the jar is not kept behind an error");

        planInstall = loc -> "plan: install\nactions:\n  START    x";
        Map<String, Object> ok;
        try (InputStream in = bundle("org.example.fine")) {
            ok = deploy.stageUpload(in, "fine.jar");
        }
        assertFalse(((String) ok.get("id")).isBlank(), "a real plan gets an id to confirm");
        assertTrue(((String) ok.get("plan")).contains("START"));
        assertEquals(1, staged());
    }
}
