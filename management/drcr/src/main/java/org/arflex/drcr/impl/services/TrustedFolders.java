package org.arflex.drcr.impl.services;

import java.io.IOException;
import java.nio.file.Path;

/**
 * The permissions a trusted folder's jar needs before the {@link CodeGate} admits it as it is
 * (issue 30 finding 5, D80), as the trust store's: the trusted folder, each folder between it
 * and the jar, and the jar owned by the runtime's user or root and not writable by group or
 * others; no folder above the trusted one writable by group or others without the sticky bit.
 * A folder with the sticky bit (the tests trust /tmp) may be writable by others: they cannot
 * replace or rename the runtime's entries there, and what they add is theirs and refused. Else
 * another user could put a jar in, or rewrite one, and have it run as the runtime's user.
 */
final class TrustedFolders {

    private TrustedFolders() {
    }

    /**
     * Null when the jar {@code file} inside the trusted folder {@code dir} (both real paths) may
     * be trusted as it is, else why not, naming the path and its mode or owner.
     */
    static String refusal(Path dir, Path file) {
        try {
            int uid = FileDoors.runtimeUid();
            Path above = FileDoors.writableAbove(dir);
            if (above != null) {
                return "the folder " + above + " above it is writable by group or others (" + FileDoors.octal(FileDoors.mode(above))
                        + "), so the trusted folder " + dir + " could be replaced";
            }
            String p = FileDoors.problem(dir, "the trusted folder", uid, true);
            Path sub = dir;
            for (Path rel : dir.relativize(file.getParent())) {
                if (p != null || rel.toString().isEmpty()) {
                    break;
                }
                sub = sub.resolve(rel);
                p = FileDoors.problem(sub, "the folder", uid, true);
            }
            return p != null ? p : FileDoors.problem(file, "the jar", uid, false);
        } catch (IOException | RuntimeException e) {
            return "cannot read the owner and mode of " + file + " or its folders: " + e.getMessage();
        }
    }
}
