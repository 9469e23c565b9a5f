package org.arflex.drcr.impl.services;

import java.io.IOException;
import java.nio.file.Files;
import java.nio.file.LinkOption;
import java.nio.file.Path;

/**
 * Whether a file or folder is a door into what the runtime trusts: one that group or others may
 * write, or that a user other than the runtime's own or root owns (who may then change its mode
 * and its content). Used for the trusted folders of the {@link CodeGate} (issue 30 finding 5,
 * D80) and the folders above the {@link TrustStore}.
 */
final class FileDoors {

    private static final int STICKY = 01000;
    private static final int GROUP_OR_OTHERS_WRITE = 0022;

    private FileDoors() {
    }

    /** The runtime's effective user id (the owner, besides root, whose files are trusted). */
    static int runtimeUid() throws IOException {
        return (Integer) Files.getAttribute(Path.of("/proc/self"), "unix:uid"); // /proc/<pid>: this process's euid
    }

    /**
     * Null when {@code p} is owned by {@code uid} or root and group and others may not write it
     * ({@code stickyOk}: unless it is a folder with the sticky bit, as /tmp, where no one
     * replaces or renames another's entries); else why not, as "{@code what} p is ...".
     */
    static String problem(Path p, String what, int uid, boolean stickyOk) throws IOException {
        int mode = mode(p);
        if ((mode & GROUP_OR_OTHERS_WRITE) != 0 && !(stickyOk && (mode & STICKY) != 0)) {
            return what + " " + p + " is writable by group or others (" + octal(mode) + ")";
        }
        int owner = (Integer) Files.getAttribute(p, "unix:uid", LinkOption.NOFOLLOW_LINKS);
        if (owner != uid && owner != 0) {
            String name = Files.getOwner(p, LinkOption.NOFOLLOW_LINKS).getName();
            return what + " " + p + " is owned by uid " + owner + (name.equals(Integer.toString(owner)) ? "" : " (" + name + ")")
                    + ", not by the runtime's user (uid " + uid + ") or root";
        }
        return null;
    }

    /** The first folder above {@code p} that group or others may write without the sticky bit, or null. */
    static Path writableAbove(Path p) throws IOException {
        for (Path up = p.getParent(); up != null; up = up.getParent()) {
            int mode = mode(up);
            if ((mode & GROUP_OR_OTHERS_WRITE) != 0 && (mode & STICKY) == 0) {
                return up;
            }
        }
        return null;
    }

    /** The permission bits of {@code p} (with set-id and sticky), links not followed. */
    static int mode(Path p) throws IOException {
        return (Integer) Files.getAttribute(p, "unix:mode", LinkOption.NOFOLLOW_LINKS) & 07777;
    }

    /** A mode as four octal digits, e.g. 0755. */
    static String octal(int mode) {
        return String.format("%04o", mode & 07777);
    }
}
