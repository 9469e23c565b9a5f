package org.arflex.webconsole.impl;

import java.io.IOException;
import java.nio.file.Files;
import java.nio.file.Path;
import java.security.SecureRandom;
import java.util.HexFormat;
import java.util.LinkedHashMap;
import java.util.Map;
import java.util.concurrent.ConcurrentHashMap;
import java.util.stream.Stream;

/**
 * Bundles staged for installation, each with the DRCR's plan, waiting for the operator's
 * confirmation under a random id: uploads and URLs of the Deploy page and the Debug page's
 * generated monitor alike; {@code api/install} and {@code api/discard} take them by id.
 */
final class StagingArea {
    private static final int MAX_STAGED = 8;

    private final Backend backend;
    private final Path dir;
    private final Map<String, Artifacts.Staged> staged = new ConcurrentHashMap<>();
    private final SecureRandom random = new SecureRandom();

    StagingArea(Backend backend, Path dir) {
        this.backend = backend;
        this.dir = dir;
    }

    /** The folder staged jars are written to. */
    Path dir() {
        return dir;
    }

    /**
     * Keeps a staged jar under a new id with the DRCR's plan for it; a jar the DRCR cannot plan
     * is deleted and the error names why.
     */
    Map<String, Object> plan(Artifacts.Staged s) throws HttpError, IOException {
        if (staged.size() >= MAX_STAGED) {
            Files.deleteIfExists(s.file());
            throw new HttpError(429, "too many staged bundles waiting for confirmation; install or discard one");
        }
        String plan;
        try {
            plan = backend.drcr().planInstall(s.file().toUri().toString());
        } catch (HttpError e) {
            Files.deleteIfExists(s.file());
            throw e;
        } catch (RuntimeException e) {
            // No plan, nothing to confirm: the staged jar goes and the error names why.
            Files.deleteIfExists(s.file());
            throw new HttpError(409, "the DRCR could not plan the install of " + s.symbolicName() + " " + s.version()
                    + " (from " + s.origin() + "), nothing staged: " + HttpError.reason(e));
        }
        byte[] id = new byte[16];
        random.nextBytes(id);
        String key = HexFormat.of().formatHex(id);
        staged.put(key, s);
        Map<String, Object> m = new LinkedHashMap<>();
        m.put("id", key);
        m.put("origin", s.origin());
        m.put("sha256", s.sha256());
        m.put("symbolicName", s.symbolicName());
        m.put("version", s.version());
        m.put("plan", plan);
        return m;
    }

    /** The staged bundle with this id, no longer staged; null when there is none. */
    Artifacts.Staged take(String id) {
        return id == null ? null : staged.remove(id);
    }

    /** Forgets every staged bundle and deletes their jars. */
    void clean() throws IOException {
        staged.clear();
        if (Files.isDirectory(dir)) {
            try (Stream<Path> s = Files.list(dir)) {
                for (Path p : s.toList()) {
                    Files.deleteIfExists(p);
                }
            }
        }
    }
}
