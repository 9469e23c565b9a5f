package org.arflex.drcr.impl.services;

import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.nio.file.Files;
import java.nio.file.Path;
import java.nio.file.attribute.PosixFilePermissions;
import java.util.ArrayList;
import java.util.List;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;

/**
 * Issue 30 finding 5: the trusted folders were trusted whatever their permissions. With
 * {@code tools/} mode 0777 a jar another user copied in was admitted, and a jar in a 0755
 * {@code tools/} but owned by another user was rewritten by that user and run as root. A trusted
 * folder, the folders between it and the jar, and the jar are now checked as the trust store is:
 * owned by the runtime's user or root, not writable by group or others, else refused with the
 * path and the mode or owner. (The unit tests run as root, the runtime's user on a cell; uid
 * 4242 stands for another user: no account is needed to own a file.)
 */
class TrustedFolderDoorsTest {

    private static final int OTHER_UID = 4242;
    private final List<String> log = new ArrayList<>();

    private static Path cellWithJar(Path dir, String folderMode, String jarMode) throws IOException {
        Path tools = Files.createDirectories(dir.resolve("tools"));
        Path jar = tools.resolve("x.jar");
        Files.write(jar, CodeGateTest.jar("payload", false));
        Files.setPosixFilePermissions(jar, PosixFilePermissions.fromString(jarMode));
        Files.setPosixFilePermissions(tools, PosixFilePermissions.fromString(folderMode));
        return jar;
    }

    private CodeGate.Decision decide(Path tools, Path jar) throws IOException {
        return new CodeGate(List.of(tools), log::add).decide(jar.toUri().toString(), ContentDigest.ofJar(jar));
    }

    @Test
    void aSoundFolderAndJarAreAdmitted(@TempDir Path dir) throws IOException {
        Path jar = cellWithJar(dir, "rwxr-xr-x", "rw-r--r--");
        CodeGate.Decision d = decide(jar.getParent(), jar);
        assertTrue(d.admitted(), d.reason());
    }

    @Test
    void aFolderOthersMayWriteIsNotTrusted(@TempDir Path dir) throws IOException {
        Path jar = cellWithJar(dir, "rwxrwxrwx", "rw-r--r--");
        CodeGate.Decision d = decide(jar.getParent(), jar);
        assertFalse(d.admitted(), d.reason());
        assertTrue(d.reason().contains("the trusted folder " + jar.getParent().toRealPath() + " is writable by group or others (0777)"),
                d.reason());
    }

    @Test
    void aGroupWritableFolderIsNotTrusted(@TempDir Path dir) throws IOException {
        Path jar = cellWithJar(dir, "rwxrwxr-x", "rw-r--r--");
        CodeGate.Decision d = decide(jar.getParent(), jar);
        assertFalse(d.admitted(), d.reason());
        assertTrue(d.reason().contains("is writable by group or others (0775)"), d.reason());
    }

    @Test
    void aJarAnotherUserOwnsIsNotTrusted(@TempDir Path dir) throws IOException {
        Path jar = cellWithJar(dir, "rwxr-xr-x", "rw-r--r--");
        Files.setAttribute(jar, "unix:uid", OTHER_UID);
        CodeGate.Decision d = decide(jar.getParent(), jar);
        assertFalse(d.admitted(), d.reason());
        assertTrue(d.reason().contains("the jar " + jar.toRealPath() + " is owned by uid " + OTHER_UID), d.reason());
    }

    @Test
    void aGroupWritableJarIsNotTrusted(@TempDir Path dir) throws IOException {
        Path jar = cellWithJar(dir, "rwxr-xr-x", "rw-rw-r--");
        CodeGate.Decision d = decide(jar.getParent(), jar);
        assertFalse(d.admitted(), d.reason());
        assertTrue(d.reason().contains("the jar " + jar.toRealPath() + " is writable by group or others (0664)"), d.reason());
    }

    @Test
    void aFolderAnotherUserOwnsIsNotTrusted(@TempDir Path dir) throws IOException {
        Path jar = cellWithJar(dir, "rwxr-xr-x", "rw-r--r--");
        Files.setAttribute(jar.getParent(), "unix:uid", OTHER_UID);
        CodeGate.Decision d = decide(jar.getParent(), jar);
        assertFalse(d.admitted(), d.reason());
        assertTrue(d.reason().contains("the trusted folder " + jar.getParent().toRealPath() + " is owned by uid " + OTHER_UID),
                d.reason());
    }

    @Test
    void aSubfolderOthersMayWriteIsNotTrusted(@TempDir Path dir) throws IOException {
        Path jar = cellWithJar(dir, "rwxr-xr-x", "rw-r--r--");
        Path sub = Files.createDirectories(jar.getParent().resolve("sub"));
        Path inner = Files.move(jar, sub.resolve("x.jar"));
        Files.setPosixFilePermissions(sub, PosixFilePermissions.fromString("rwxrwxrwx"));
        CodeGate.Decision d = decide(jar.getParent(), inner);
        assertFalse(d.admitted(), d.reason());
        assertTrue(d.reason().contains("the folder " + sub.toRealPath() + " is writable by group or others (0777)"),
                d.reason());
    }

    @Test
    void aStickyFolderAboveTheTrustedOneIsNoDoorButAPlainWritableOneIs(@TempDir Path dir) throws IOException {
        Path jar = cellWithJar(dir, "rwxr-xr-x", "rw-r--r--");
        // the tests' temporary folders live under /tmp (1777): sticky, so no one replaces tools/
        Files.setAttribute(dir, "unix:mode", 01777);
        assertTrue(decide(jar.getParent(), jar).admitted());
        Files.setPosixFilePermissions(dir, PosixFilePermissions.fromString("rwxrwxrwx"));
        CodeGate.Decision d = decide(jar.getParent(), jar);
        assertFalse(d.admitted(), d.reason());
        assertTrue(d.reason().contains("the folder " + dir.toRealPath() + " above it is writable by group or others (0777)"),
                d.reason());
    }

    @Test
    void aStickyTrustedFolderAdmitsOnlyWhatTheRuntimesUserOwns(@TempDir Path dir) throws IOException {
        // as the tests trust /tmp: others may add files there, never replace the runtime's
        Path jar = cellWithJar(dir, "rwxr-xr-x", "rw-r--r--");
        Files.setAttribute(jar.getParent(), "unix:mode", 01777);
        assertTrue(decide(jar.getParent(), jar).admitted());
        Files.setAttribute(jar, "unix:uid", OTHER_UID);
        CodeGate.Decision d = decide(jar.getParent(), jar);
        assertFalse(d.admitted(), d.reason());
        assertTrue(d.reason().contains("is owned by uid " + OTHER_UID), d.reason());
    }
}
