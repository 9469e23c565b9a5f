package org.arflex.webconsole.impl;

import java.io.IOException;
import java.net.URI;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;

/**
 * The folders a {@code file:} URL may stage a bundle from (framework property
 * {@value #PROPERTY}, comma-separated). With none configured, every {@code file:} URL is
 * refused: otherwise the console would report the SHA-256 of any file the runtime can read
 * (issue 16, finding 8).
 *
 * <p>Decisions: containment is checked on the normalised path before the file is looked at, so
 * a refusal says nothing about whether a file outside exists; then again on the real path, so
 * a symbolic link inside a folder cannot lead out of it.
 */
final class StagingSources {
    /** The framework property naming the folders. */
    static final String PROPERTY = "arflex.console.stage.dirs";

    private final List<Path> folders;

    private StagingSources(List<Path> folders) {
        this.folders = List.copyOf(folders);
    }

    /** The folders named in {@code property} (null or blank: none). */
    static StagingSources parse(String property) {
        List<Path> folders = new ArrayList<>();
        if (property != null) {
            for (String f : property.split(",")) {
                if (!f.isBlank()) {
                    folders.add(Path.of(f.trim()).toAbsolutePath().normalize());
                }
            }
        }
        return new StagingSources(folders);
    }

    /** The file a {@code file:} URL names, when it lies in a configured folder; else why not. */
    Path file(URI u) throws HttpError, IOException {
        if (folders.isEmpty()) {
            throw new HttpError(400, "url: file: URLs are refused: no folder is configured for them (framework"
                    + " property " + PROPERTY + "); upload the jar instead");
        }
        Path p;
        try {
            p = Path.of(u).toAbsolutePath().normalize();
        } catch (IllegalArgumentException | java.nio.file.FileSystemNotFoundException e) {
            throw new HttpError(400, "url: not a file path (" + e.getMessage() + ")");
        }
        if (folders.stream().noneMatch(p::startsWith)) {
            throw outside(u);
        }
        if (!Files.isRegularFile(p)) {
            throw new HttpError(400, "url: no such file " + p);
        }
        Path real = p.toRealPath();
        for (Path f : folders) {
            if (Files.isDirectory(f) && real.startsWith(f.toRealPath())) {
                return real;
            }
        }
        throw outside(u);
    }

    private HttpError outside(URI u) {
        return new HttpError(400, "url: " + u + " is outside the folders configured for file: URLs (" + folders
                + ", framework property " + PROPERTY + ")");
    }
}
