package org.arflex.webconsole.impl;

import java.io.IOException;
import java.io.InputStream;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.LinkedHashMap;
import java.util.Map;
import org.arflex.drcr.DrcrService;
import org.arflex.drcr.UpdateService;
import org.arflex.drcr.dto.ContractDTO;
import org.osgi.framework.Bundle;
import org.osgi.framework.BundleException;

/**
 * The Deploy page's endpoints: stage a bundle (upload or URL with a pinned SHA-256) with the
 * DRCR's plan, install or discard it, plan and confirm an update from the contract's update URL,
 * plan and confirm an uninstall. The Debug page installs and removes its monitor through them too.
 */
final class DeployBackend {
    private final Backend backend;
    private final StagingArea staging;
    private final Path installed;
    private final StagingSources stageSources;

    DeployBackend(Backend backend, StagingArea staging, Path installed, StagingSources stageSources) {
        this.backend = backend;
        this.staging = staging;
        this.installed = installed;
        this.stageSources = stageSources;
    }

    Routes routes() {
        return new Routes()
                .get("plan-uninstall", call -> planUninstall(call.name()))
                .post("stage-url", call -> stageUrl(call.param("url"), call.param("sha256")))
                .post("stage-upload", call -> {
                    try (InputStream in = call.body()) {
                        return stageUpload(in, call.param("file"));
                    }
                })
                .post("install", call -> installStaged(call.param("id")))
                .post("discard", call -> discard(call.param("id")))
                .post("uninstall", call -> uninstall(call.name()))
                // A dry run, but it makes the DRCR download the update: CSRF-checked like stage-url.
                .post("plan-update", call -> planUpdate(call.name()))
                .post("update", call -> update(call.name(), call.param("sha256")));
    }

    /** Stages a bundle from a URL with a pinned hash and returns its plan. */
    Map<String, Object> stageUrl(String url, String sha256) throws HttpError, IOException {
        var u = Artifacts.checkUrl(url, sha256);
        return staging.plan(Artifacts.fetch(u, sha256, staging.dir(), stageSources));
    }

    /** Stages an uploaded bundle and returns its plan. */
    Map<String, Object> stageUpload(InputStream body, String fileName) throws HttpError, IOException {
        return staging.plan(Artifacts.upload(body, fileName, staging.dir()));
    }

    /** Installs (or updates, when a bundle with that symbolic name exists) a staged bundle. */
    Map<String, Object> installStaged(String id) throws HttpError, IOException {
        Artifacts.Staged s = staging.take(id);
        if (s == null) {
            throw new HttpError(404, "id: no staged bundle with this id (expired or already installed)");
        }
        Path kept = Artifacts.keep(s, installed);
        String location = kept.toUri().toString();
        // The DRCR runs RT halves only of code verified against a pin (docs/DECISIONS.md D12):
        // the staged jar was checked against the SHA-256 the operator pinned and confirmed.
        UpdateService u = backend.updates;
        if (u == null) {
            throw new HttpError(503, "the DRCR is not running (no UpdateService registered)");
        }
        try {
            u.verified(Files.readAllBytes(kept), s.sha256(), "console Deploy of " + s.origin());
        } catch (IllegalArgumentException e) {
            throw new HttpError(409, "install of " + s.symbolicName() + " refused: " + e.getMessage());
        }
        try (InputStream in = Files.newInputStream(kept)) {
            Bundle existing = backend.bundleNamed(s.symbolicName());
            Bundle b;
            String action;
            if (existing != null) {
                existing.update(in);
                b = existing;
                action = "updated";
            } else {
                b = backend.context().installBundle(location, in);
                action = "installed";
            }
            b.start();
            return Map.of("bundleId", b.getBundleId(), "symbolicName", s.symbolicName(), "action", action,
                    "sha256", s.sha256());
        } catch (BundleException e) {
            throw new HttpError(409, "install of " + s.symbolicName() + " failed: " + e.getMessage());
        }
    }

    /** Drops a staged bundle without installing it. */
    Map<String, Object> discard(String id) throws IOException {
        Artifacts.Staged s = staging.take(id);
        if (s != null) {
            Files.deleteIfExists(s.file());
        }
        return Map.of("discarded", s != null);
    }

    Map<String, Object> planUninstall(String name) throws HttpError {
        Names.checkName(name);
        return Map.of("component", name, "plan", backend.drcr().planUninstall(name));
    }

    Map<String, Object> uninstall(String name) throws HttpError {
        Bundle b = backend.bundleOf(name);
        long id = b.getBundleId();
        try {
            b.uninstall();
        } catch (BundleException e) {
            throw new HttpError(409, "uninstall of " + name + " failed: " + e.getMessage());
        }
        return Map.of("component", name, "bundleId", id, "action", "uninstalled");
    }

    /**
     * The DRCR's dry run of {@code update name}: it downloads from the contract's update URL,
     * checks the pinned SHA-256 and the new contracts, and plans the replacement without
     * installing anything. A failure (no update URL, download, hash mismatch, broken bundle) is
     * an error (404 unknown component, 409 otherwise), never a plan that could be confirmed.
     */
    Map<String, Object> planUpdate(String name) throws HttpError {
        Names.checkName(name);
        DrcrService d = backend.drcr();
        ContractDTO c = d.contract(name).orElseThrow(
                () -> new HttpError(404, "cannot plan the update of " + name + ": no component named '" + name
                        + "' in the cell"));
        String plan;
        try {
            plan = d.planUpdate(name);
        } catch (IllegalArgumentException e) {
            throw new HttpError(404, "cannot plan the update of " + name + ": " + unprefixed(name, HttpError.reason(e)));
        } catch (RuntimeException e) {
            throw new HttpError(409, "cannot plan the update of " + name + ": " + unprefixed(name, HttpError.reason(e)));
        }
        Map<String, Object> m = new LinkedHashMap<>();
        m.put("component", name);
        m.put("version", c.version);
        m.put("updateUrl", c.updateUrl);
        m.put("sha256", c.updateSha256);
        m.put("plan", plan);
        return m;
    }

    /**
     * Updates from the contract's update URL. With {@code sha256} (the pin the shown plan was
     * made for), a contract that pins something else by now is refused: plan again.
     */
    Map<String, Object> update(String name, String sha256) throws HttpError {
        Names.checkName(name);
        UpdateService u = backend.updates;
        if (u == null) {
            throw new HttpError(503, "no UpdateService registered (DRCR not running)");
        }
        if (sha256 != null && !sha256.isBlank()) {
            String pinned = backend.drcr().contract(name).map(c -> c.updateSha256).orElse(null);
            if (pinned == null || !pinned.equalsIgnoreCase(sha256.trim())) {
                throw new HttpError(409, "update of " + name + " refused: the contract now pins "
                        + (pinned == null ? "no update" : "SHA-256 " + pinned) + ", the plan shown was for " + sha256.trim()
                        + "; plan the update again");
            }
        }
        try {
            return Map.of("component", name, "report", u.update(name));
        } catch (IllegalStateException | IllegalArgumentException e) {
            throw new HttpError(409, "update of " + name + " refused: " + e.getMessage());
        }
    }

    /** The DRCR starts its update messages with "name: "; said once is enough. */
    private static String unprefixed(String name, String message) {
        return message.startsWith(name + ": ") ? message.substring(name.length() + 2) : message;
    }
}
