package org.arflex.drcr.impl;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.file.Files;
import java.nio.file.Path;
import java.nio.file.attribute.PosixFilePermissions;
import java.util.ArrayList;
import java.util.List;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;

/** Issue 16 finding 5: a framework storage made under umask 000 is closed when the DRCR starts. */
class StoragePermissionsTest {

    @TempDir
    Path tmp;

    private final List<String> log = new ArrayList<>();

    @Test
    void aStorageOthersCouldWriteIsClosedAndTheUmaskSet() throws Exception {
        Path cache = tmp.resolve("felix-cache");
        Path jar = Files.createDirectories(cache.resolve("bundle7/version0.0")).resolve("bundle.jar");
        Files.writeString(jar, "code");
        for (Path p : List.of(cache, cache.resolve("bundle7"), cache.resolve("bundle7/version0.0"))) {
            Files.setPosixFilePermissions(p, PosixFilePermissions.fromString("rwxrwxrwx"));
        }
        Files.setPosixFilePermissions(jar, PosixFilePermissions.fromString("rw-rw-rw-"));
        int[] set = {-1};
        List<Path> closed = StoragePermissions.secure(cache, m -> {
            set[0] = m;
            return 0;
        }, log::add);
        assertEquals(077, set[0]);
        assertEquals(4, closed.size(), closed.toString());
        assertEquals("rw-r--r--", PosixFilePermissions.toString(Files.getPosixFilePermissions(jar)));
        assertEquals("rwxr-xr-x", PosixFilePermissions.toString(Files.getPosixFilePermissions(cache)));
        assertEquals(1, log.size());
        assertTrue(log.get(0).contains("umask 000") && log.get(0).contains("4 entries") && log.get(0).contains("run-cell.sh"),
                log.get(0));
    }

    @Test
    void aClosedStorageUnderAUsualUmaskSaysNothing() throws Exception {
        Path cache = Files.createDirectories(tmp.resolve("felix-cache/bundle1"));
        Files.setPosixFilePermissions(cache, PosixFilePermissions.fromString("rwx------"));
        List<Path> closed = StoragePermissions.secure(tmp.resolve("felix-cache"), m -> 022, log::add);
        assertEquals(List.of(), closed);
        assertEquals(List.of(), log);
    }
}
