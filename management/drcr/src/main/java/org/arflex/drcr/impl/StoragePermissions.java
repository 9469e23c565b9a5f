package org.arflex.drcr.impl;

import java.io.IOException;
import java.nio.file.FileVisitResult;
import java.nio.file.Files;
import java.nio.file.LinkOption;
import java.nio.file.Path;
import java.nio.file.SimpleFileVisitor;
import java.nio.file.attribute.BasicFileAttributes;
import java.nio.file.attribute.PosixFilePermission;
import java.util.ArrayList;
import java.util.EnumSet;
import java.util.List;
import java.util.Set;
import java.util.function.Consumer;
import java.util.function.IntUnaryOperator;

/**
 * The framework's storage is code (issue 16 finding 5): Felix keeps every installed bundle's jar
 * in {@code felix-cache/bundleN/version*} and loads it again at the next start, as root. Started
 * under umask 000 (a service manager, a shell someone left so), those files and folders were
 * writable by every user. {@code scripts/run-cell.sh} starts the JVM under umask 077; this is
 * the second line, for any other way of starting it: when the DRCR starts it sets the process
 * umask to 077 (so nothing created later is open) and takes group and other write permission
 * off everything in the storage, saying how much it found open. Felix's own files created before
 * the DRCR started were open for that moment: docs/DECISIONS.md D12 says so.
 */
final class StoragePermissions {

    private static final Set<PosixFilePermission> OTHERS = EnumSet.of(PosixFilePermission.GROUP_WRITE,
            PosixFilePermission.OTHERS_WRITE);

    private StoragePermissions() {
    }

    /**
     * @param umask sets the process umask, returns the previous one (libc umask)
     * @return the paths that others could write (now they cannot)
     */
    static List<Path> secure(Path storage, IntUnaryOperator umask, Consumer<String> log) throws IOException {
        int previous = umask.applyAsInt(077);
        List<Path> opened = new ArrayList<>();
        if (Files.isDirectory(storage, LinkOption.NOFOLLOW_LINKS)) {
            Files.walkFileTree(storage, new SimpleFileVisitor<>() {
                @Override
                public FileVisitResult preVisitDirectory(Path dir, BasicFileAttributes attrs) throws IOException {
                    close(dir);
                    return FileVisitResult.CONTINUE;
                }

                @Override
                public FileVisitResult visitFile(Path file, BasicFileAttributes attrs) throws IOException {
                    if (!attrs.isSymbolicLink()) {
                        close(file);
                    }
                    return FileVisitResult.CONTINUE;
                }

                private void close(Path p) throws IOException {
                    Set<PosixFilePermission> s = Files.getPosixFilePermissions(p, LinkOption.NOFOLLOW_LINKS);
                    if (s.stream().anyMatch(OTHERS::contains)) {
                        s.removeAll(OTHERS);
                        Files.setPosixFilePermissions(p, s);
                        opened.add(p);
                    }
                }
            });
        }
        if ((previous & 022) != 022 || !opened.isEmpty()) {
            log.accept(String.format("arflex: the runtime was started under umask %03o: umask now 077; %d entries of %s"
                    + " were writable by group or others and are not any more%s (start it with scripts/run-cell.sh, which sets"
                    + " umask 077)", previous, opened.size(), storage.toAbsolutePath(),
                    opened.isEmpty() ? "" : ", first " + opened.get(0)));
        }
        return opened;
    }
}
