package org.arflex.drcr.impl.supervisor;

import static org.junit.jupiter.api.Assertions.assertArrayEquals;
import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertThrows;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.ByteArrayInputStream;
import java.io.IOException;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.nio.file.attribute.FileTime;
import java.nio.file.attribute.PosixFilePermissions;
import java.util.ArrayList;
import java.util.List;
import java.util.concurrent.atomic.AtomicReference;
import org.arflex.drcr.impl.abi.ControlBlock;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;

/**
 * Issue 16 finding 5: under umask 000 the extracted native folder was 0777 and an executable
 * newer than its bundle was reused, so a replaced RT half ran as root at the next restart.
 */
class VerifiedExecutablesTest {

    private final List<String> log = new ArrayList<>();

    private static byte[] script(String marker) {
        return ("#!/bin/sh\ntouch '" + marker + "'\nexit 3\n").getBytes(StandardCharsets.UTF_8);
    }

    private static String perms(Path p) throws IOException {
        return PosixFilePermissions.toString(Files.getPosixFilePermissions(p));
    }

    @Test
    void theFolderIs0700AndTheFile0500EvenWhenTheyWereWorldWritable(@TempDir Path root) throws IOException {
        Path data = Files.createDirectories(root.resolve("bundle12/data"));
        Path dir = Files.createDirectories(data.resolve("arflex-native"));
        Path old = dir.resolve("rt");
        Files.writeString(old, "planted");
        for (Path p : List.of(root.resolve("bundle12"), data, dir, old)) {
            Files.setPosixFilePermissions(p, PosixFilePermissions.fromString("rwxrwxrwx"));
        }
        byte[] exe = script("/nonexistent");
        Path got = new VerifiedExecutables(root, log::add).extract(dir, "rt", () -> new ByteArrayInputStream(exe));

        assertEquals(old, got);
        assertArrayEquals(exe, Files.readAllBytes(got));
        assertEquals("rwx------", perms(dir));
        assertEquals("r-x------", perms(got));
        assertEquals("rwxr-xr-x", perms(data), "a parent inside the storage must not be writable by others");
        assertEquals("rwxr-xr-x", perms(root.resolve("bundle12")));
        try (var s = Files.list(dir)) {
            assertEquals(List.of(got), s.toList(), "no temporary file left");
        }
    }

    @Test
    void aFolderCreatedByTheExtractionIsPrivateFromTheStart(@TempDir Path root) throws IOException {
        Path dir = root.resolve("a/b/arflex-native");
        Path got = new VerifiedExecutables(root, log::add).extract(dir, "rt", () -> new ByteArrayInputStream(new byte[] {1}));
        assertEquals("rwx------", perms(dir));
        assertEquals("r-x------", perms(got));
    }

    @Test
    void aForgottenExecutableReleasesItsSourceAndIsNeverRunAgain(@TempDir Path root) throws IOException {
        VerifiedExecutables v = new VerifiedExecutables(root, log::add);
        Path a = v.extract(root.resolve("bundle7/native"), "rt", () -> new ByteArrayInputStream(new byte[] {1}));
        Path b = v.extract(root.resolve("bundle8/native"), "rt", () -> new ByteArrayInputStream(new byte[] {2}));
        assertEquals(2, v.size());
        v.forget(a); // bundle 7 uninstalled
        assertEquals(1, v.size(), "one record per bundle still installed, none per cycle");
        IOException e = assertThrows(IOException.class, () -> v.verify(a));
        assertTrue(e.getMessage().contains("not extracted from a bundle"), e.getMessage());
        assertEquals(b, v.verify(b));
    }

    @Test
    void aReplacedExecutableIsExtractedAgainBeforeItRuns(@TempDir Path root) throws IOException {
        byte[] exe = script(root.resolve("ran").toString());
        VerifiedExecutables v = new VerifiedExecutables(root, log::add);
        Path got = v.extract(root.resolve("native"), "rt", () -> new ByteArrayInputStream(exe));
        String recorded = v.recorded(got);

        // an attacker's file: other bytes, newer than anything (the old check reused it)
        Files.setPosixFilePermissions(got, PosixFilePermissions.fromString("rwx------"));
        Files.writeString(got, "#!/bin/sh\necho evil\n");
        Files.setLastModifiedTime(got, FileTime.fromMillis(System.currentTimeMillis() + 86_400_000L));

        assertEquals(got, v.verify(got));
        assertArrayEquals(exe, Files.readAllBytes(got), "the bundle's bytes are back");
        assertEquals("r-x------", perms(got));
        assertTrue(log.stream().anyMatch(l -> l.contains(got.toString()) && l.contains(recorded)), log.toString());
    }

    @Test
    void whenTheBundlesCopyDiffersTooTheSpawnIsRefusedWithBothHashes(@TempDir Path root) throws IOException {
        AtomicReference<byte[]> bundle = new AtomicReference<>(script(root.resolve("ran").toString()));
        VerifiedExecutables v = new VerifiedExecutables(root, log::add);
        Path got = v.extract(root.resolve("native"), "rt", () -> new ByteArrayInputStream(bundle.get()));
        String recorded = v.recorded(got);
        Files.setPosixFilePermissions(got, PosixFilePermissions.fromString("rwx------"));
        Files.writeString(got, "#!/bin/sh\necho evil\n");
        bundle.set("#!/bin/sh\necho also evil\n".getBytes(StandardCharsets.UTF_8));

        IOException e = assertThrows(IOException.class, () -> v.verify(got));
        assertTrue(e.getMessage().contains(got.toString()), e.getMessage());
        assertTrue(e.getMessage().contains(recorded), e.getMessage());
        assertTrue(e.getMessage().contains(VerifiedExecutables.sha256(got)), e.getMessage());
    }

    @Test
    void aFileNobodyExtractedIsNeverRun(@TempDir Path root) throws IOException {
        Path exe = root.resolve("rt");
        Files.write(exe, script(root.resolve("ran").toString()));
        IOException e = assertThrows(IOException.class, () -> new VerifiedExecutables(root, log::add).verify(exe));
        assertTrue(e.getMessage().contains("not extracted"), e.getMessage());
    }

    /** The launcher checks before every spawn: the replaced file does not run. */
    @Test
    void theLauncherDoesNotSpawnAReplacedExecutable(@TempDir Path root) throws IOException {
        Path ran = root.resolve("ran");
        AtomicReference<byte[]> bundle = new AtomicReference<>(script(ran.toString()));
        VerifiedExecutables v = new VerifiedExecutables(root, log::add);
        Path got = v.extract(root.resolve("native"), "rt", () -> new ByteArrayInputStream(bundle.get()));
        Path evil = root.resolve("evil-ran");
        Files.setPosixFilePermissions(got, PosixFilePermissions.fromString("rwx------"));
        Files.writeString(got, "#!/bin/sh\ntouch '" + evil + "'\n");
        bundle.set(Files.readAllBytes(got));
        String rid = "vt" + ProcessHandle.current().pid();
        RtLauncher.Spec spec = new RtLauncher.Spec(rid, "replaced", got,
                new ControlBlock.Config(1_000_000, 1_000_000, 0, 0, 0, 0, 0, 0), List.of(), false, 2_000);

        IOException e = assertThrows(IOException.class, () -> new ProcessLauncher(log::add, v).launch(spec));
        assertTrue(e.getMessage().startsWith("refused to run"), e.getMessage());
        assertFalse(Files.exists(evil), "the replaced executable ran");
        assertFalse(Files.exists(Path.of("/dev/shm" + ProcessLauncher.objectName(rid, "replaced", "ctl"))));
    }
}
