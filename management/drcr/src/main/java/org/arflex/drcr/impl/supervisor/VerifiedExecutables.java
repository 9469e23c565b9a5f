package org.arflex.drcr.impl.supervisor;

import java.io.IOException;
import java.io.InputStream;
import java.io.OutputStream;
import java.nio.file.Files;
import java.nio.file.LinkOption;
import java.nio.file.Path;
import java.nio.file.StandardCopyOption;
import java.nio.file.attribute.PosixFileAttributes;
import java.nio.file.attribute.PosixFilePermission;
import java.nio.file.attribute.PosixFilePermissions;
import java.nio.file.attribute.UserPrincipal;
import java.security.DigestOutputStream;
import java.security.MessageDigest;
import java.security.NoSuchAlgorithmException;
import java.util.EnumSet;
import java.util.HexFormat;
import java.util.Map;
import java.util.Set;
import java.util.concurrent.ConcurrentHashMap;
import java.util.function.Consumer;

/**
 * The native half that runs is the one that was verified (issue 16 finding 5). Executables are
 * copied out of their bundle into a folder the runtime makes 0700, as files 0500, whatever the
 * umask; the SHA-256 of the bundle's entry is recorded as it is copied. Before every spawn
 * ({@link #verify}, called by {@link ProcessLauncher#launch} only) the file on disk is hashed
 * again: a file that differs is extracted afresh from its bundle, and if that copy still does
 * not match the record the spawn is refused, naming the file and both hashes. A file nobody
 * extracted through here is never run. Nothing is reused by timestamp.
 *
 * <p>Thread-safe: the extender extracts on the framework's thread, the actor spawns.
 */
public final class VerifiedExecutables {

    /** Where an executable comes from: opened again when the copy on disk must be replaced. */
    @FunctionalInterface
    public interface Source {
        InputStream open() throws IOException;
    }

    private record Entry(String sha256, Source source) {
    }

    static final Set<PosixFilePermission> DIR = PosixFilePermissions.fromString("rwx------");
    static final Set<PosixFilePermission> FILE = PosixFilePermissions.fromString("r-x------");
    private static final Set<PosixFilePermission> TMP = PosixFilePermissions.fromString("rw-------");
    private static final Set<PosixFilePermission> GROUP_OR_OTHER_WRITE = EnumSet.of(
            PosixFilePermission.GROUP_WRITE, PosixFilePermission.OTHERS_WRITE);

    private final Map<Path, Entry> extracted = new ConcurrentHashMap<>();
    private final Path root;
    private final Consumer<String> log;

    /**
     * @param root the runtime's storage (Felix's {@code felix-cache}): the folders between it and
     *             an extraction folder are kept unwritable by others
     */
    public VerifiedExecutables(Path root, Consumer<String> log) {
        this.root = root.toAbsolutePath().normalize();
        this.log = log;
    }

    /**
     * Copies {@code source} to {@code dir/name} (the folder 0700, the file 0500) and records the
     * SHA-256 of what was read.
     *
     * @return the extracted file
     */
    public Path extract(Path dir, String name, Source source) throws IOException {
        Path d = dir.toAbsolutePath().normalize();
        Path target = d.resolve(name).normalize();
        if (!target.getParent().equals(d)) {
            throw new IOException("executable name '" + name + "' leaves its folder");
        }
        String sha = copy(d, target, source);
        extracted.put(target, new Entry(sha, source));
        return target;
    }

    /**
     * Drops the record of {@code exe} (its bundle was updated or uninstalled): {@link #verify}
     * refuses it from now on, and the record's source, which reads from the bundle, no longer
     * keeps that bundle revision in memory (issue 17 finding 2: one record per install cycle
     * was never released).
     */
    public void forget(Path exe) {
        extracted.remove(exe.toAbsolutePath().normalize());
    }

    /** Records held (one per executable extracted and not forgotten). */
    public int size() {
        return extracted.size();
    }

    /** The SHA-256 recorded for an extracted executable, or null. */
    public String recorded(Path exe) {
        Entry e = extracted.get(exe.toAbsolutePath().normalize());
        return e == null ? null : e.sha256();
    }

    /**
     * Makes sure {@code exe} is what was extracted: its folder private, its bytes those recorded.
     *
     * @return the path to execute
     * @throws IOException why it must not run
     */
    public Path verify(Path exe) throws IOException {
        Path target = exe.toAbsolutePath().normalize();
        Entry e = extracted.get(target);
        if (e == null) {
            throw new IOException("refused to run " + target + ": it was not extracted from a bundle by the DRCR");
        }
        privateFolder(target.getParent());
        String onDisk = Files.isRegularFile(target, LinkOption.NOFOLLOW_LINKS) ? sha256(target) : "(no regular file)";
        if (onDisk.equals(e.sha256())) {
            Files.setPosixFilePermissions(target, FILE);
            return target;
        }
        log.accept("arflex: " + target + " has SHA-256 " + onDisk + ", extracted with " + e.sha256()
                + ": extracting it again from its bundle");
        String again = copy(target.getParent(), target, e.source());
        if (!again.equals(e.sha256())) {
            throw new IOException("refused to run " + target + ": SHA-256 " + again + " of the bundle's copy differs from "
                    + e.sha256() + " recorded at install (the file on disk had " + onDisk + ")");
        }
        return target;
    }

    /** Copies into a private temporary file, then renames it over the target; returns the SHA-256. */
    private String copy(Path dir, Path target, Source source) throws IOException {
        privateFolder(dir);
        Path tmp = Files.createTempFile(dir, target.getFileName().toString(), ".tmp",
                PosixFilePermissions.asFileAttribute(TMP));
        try {
            Files.setPosixFilePermissions(tmp, TMP);
            MessageDigest md = sha256();
            try (InputStream in = source.open(); OutputStream out = new DigestOutputStream(Files.newOutputStream(tmp), md)) {
                if (in == null) {
                    throw new IOException("not in the bundle");
                }
                in.transferTo(out);
            }
            Files.setPosixFilePermissions(tmp, FILE);
            Files.move(tmp, target, StandardCopyOption.REPLACE_EXISTING, StandardCopyOption.ATOMIC_MOVE);
            return HexFormat.of().formatHex(md.digest());
        } finally {
            Files.deleteIfExists(tmp);
        }
    }

    /**
     * Creates the folder 0700 (or makes it so) and refuses one that is a link or not ours. Its
     * parents up to the runtime's storage root are made unwritable by group and others (under
     * umask 000 Felix creates them 0777, and whoever may write a parent may rename our folder
     * away and put theirs in its place); above the root nothing is touched.
     */
    void privateFolder(Path dir) throws IOException {
        if (!Files.exists(dir, LinkOption.NOFOLLOW_LINKS)) {
            Files.createDirectories(dir.getParent());
            Files.createDirectory(dir, PosixFilePermissions.asFileAttribute(DIR));
        }
        PosixFileAttributes a = Files.readAttributes(dir, PosixFileAttributes.class, LinkOption.NOFOLLOW_LINKS);
        if (!a.isDirectory()) {
            throw new IOException(dir + " is not a folder (a link or a file)");
        }
        UserPrincipal me = dir.getFileSystem().getUserPrincipalLookupService()
                .lookupPrincipalByName(System.getProperty("user.name"));
        if (!a.owner().equals(me)) {
            throw new IOException(dir + " belongs to " + a.owner() + ", not to the runtime's user " + me);
        }
        Files.setPosixFilePermissions(dir, DIR);
        if (!dir.startsWith(root)) {
            return;
        }
        for (Path p = dir.getParent(); p != null && p.startsWith(root); p = p.getParent()) {
            PosixFileAttributes pa = Files.readAttributes(p, PosixFileAttributes.class, LinkOption.NOFOLLOW_LINKS);
            Set<PosixFilePermission> perms = EnumSet.noneOf(PosixFilePermission.class);
            perms.addAll(pa.permissions());
            if (perms.removeAll(GROUP_OR_OTHER_WRITE)) {
                if (!pa.owner().equals(me)) {
                    throw new IOException(p + " is writable by others and not ours: " + dir + " could be replaced");
                }
                Files.setPosixFilePermissions(p, perms);
                log.accept("arflex: " + p + " was writable by group or others: made " + PosixFilePermissions.toString(perms));
            }
        }
    }

    static String sha256(Path file) throws IOException {
        MessageDigest md = sha256();
        try (InputStream in = Files.newInputStream(file, LinkOption.NOFOLLOW_LINKS)) {
            byte[] buf = new byte[65536];
            int n;
            while ((n = in.read(buf)) > 0) {
                md.update(buf, 0, n);
            }
        }
        return HexFormat.of().formatHex(md.digest());
    }

    private static MessageDigest sha256() {
        try {
            return MessageDigest.getInstance("SHA-256");
        } catch (NoSuchAlgorithmException e) {
            throw new IllegalStateException(e);
        }
    }
}
