package org.arflex.drcr.impl.services;

import java.io.IOException;
import java.nio.ByteBuffer;
import java.nio.channels.FileChannel;
import java.nio.channels.SeekableByteChannel;
import java.nio.file.DirectoryStream;
import java.nio.file.FileAlreadyExistsException;
import java.nio.file.Files;
import java.nio.file.LinkOption;
import java.nio.file.NoSuchFileException;
import java.nio.file.Path;
import java.nio.file.StandardCopyOption;
import java.nio.file.StandardOpenOption;
import java.nio.file.attribute.PosixFileAttributes;
import java.nio.file.attribute.PosixFilePermission;
import java.nio.file.attribute.PosixFilePermissions;
import java.security.SecureRandom;
import java.time.ZoneOffset;
import java.time.format.DateTimeFormatter;
import java.util.EnumSet;
import java.util.HexFormat;
import java.util.List;
import java.util.Locale;
import java.util.Set;
import java.util.function.Consumer;
import org.arflex.drcr.dto.ChangeSetDTO;

/**
 * The change-set history's file in the DRCR's data area (D66): read once when the DRCR starts,
 * written whole after each record. Read only when it is a regular file (never through a link),
 * owned by the runtime's uid, open to nobody else, at most {@link #MAX_BYTES}, and whole
 * ({@link HistoryFormat}); anything else is refused with a log line naming the path and what is
 * wrong, and set aside under a new name beside it (never overwritten, never deleted): the history
 * then starts empty. Written atomically: a new temporary file beside it (created exclusively,
 * mode 0600, never through a link), synced, renamed over the path (which replaces a link, never
 * its target), then the folder synced.
 */
final class HistoryFile {

    /** The file's name in the data area. */
    static final String NAME = "changeset-history";
    /** A history of {@link ChangeSetHistory#MAX} sets with their plans is far smaller. */
    static final long MAX_BYTES = 8L << 20;

    private static final Set<PosixFilePermission> OPEN = EnumSet.of(PosixFilePermission.GROUP_READ,
            PosixFilePermission.GROUP_WRITE, PosixFilePermission.GROUP_EXECUTE, PosixFilePermission.OTHERS_READ,
            PosixFilePermission.OTHERS_WRITE, PosixFilePermission.OTHERS_EXECUTE);
    private static final DateTimeFormatter STAMP = DateTimeFormatter.ofPattern("yyyyMMdd'T'HHmmss'Z'", Locale.ROOT)
            .withZone(ZoneOffset.UTC);
    private static final SecureRandom RANDOM = new SecureRandom();

    private final Path file;
    private final long uid;
    private final Consumer<String> log;
    /** Set when a refused file could not be set aside: nothing is written over it. */
    private volatile String blocked;

    /**
     * @param folder the DRCR's data area (its own folder)
     * @param uid the runtime's effective uid: the only owner a history file may have
     */
    HistoryFile(Path folder, long uid, Consumer<String> log) {
        this.file = folder.toAbsolutePath().normalize().resolve(NAME); // the log names it whole
        this.uid = uid;
        this.log = log;
    }

    Path path() {
        return file;
    }

    /** The records kept (newest first); empty when there is no file or it was refused. */
    List<ChangeSetDTO> load() {
        sweepTemporaries();
        PosixFileAttributes a;
        try {
            a = Files.readAttributes(file, PosixFileAttributes.class, LinkOption.NOFOLLOW_LINKS);
        } catch (NoSuchFileException e) {
            return List.of();
        } catch (IOException e) {
            refuse("cannot be looked at (" + e + ")");
            return List.of();
        }
        String wrong = wrong(a);
        if (wrong != null) {
            refuse(wrong);
            return List.of();
        }
        byte[] bytes;
        try (SeekableByteChannel ch = Files.newByteChannel(file, Set.of(StandardOpenOption.READ, LinkOption.NOFOLLOW_LINKS))) {
            // what was opened is what was looked at: not swapped for another file meanwhile
            PosixFileAttributes again = Files.readAttributes(file, PosixFileAttributes.class, LinkOption.NOFOLLOW_LINKS);
            if (a.fileKey() == null || !a.fileKey().equals(again.fileKey()) || wrong(again) != null) {
                refuse("was replaced while it was opened");
                return List.of();
            }
            bytes = readAll(ch);
        } catch (IOException e) {
            refuse("cannot be read (" + e + ")");
            return List.of();
        }
        try {
            List<ChangeSetDTO> l = HistoryFormat.read(bytes);
            log.accept("arflex: change-set history: " + l.size() + " sets read from " + file);
            return l.size() > ChangeSetHistory.MAX ? l.subList(0, ChangeSetHistory.MAX) : l;
        } catch (HistoryFormat.Bad e) {
            refuse("is damaged: " + e.getMessage());
            return List.of();
        }
    }

    /** What makes the file at the path not one to read, or null. */
    private String wrong(PosixFileAttributes a) {
        if (a.isSymbolicLink()) {
            String to;
            try {
                to = String.valueOf(Files.readSymbolicLink(file));
            } catch (IOException e) {
                to = "?";
            }
            return "is a symbolic link (to " + to + "): not followed";
        }
        if (!a.isRegularFile()) {
            return "is not a regular file (" + (a.isDirectory() ? "a folder" : "a device, FIFO or socket") + ")";
        }
        long owner;
        try {
            owner = ((Number) Files.getAttribute(file, "unix:uid", LinkOption.NOFOLLOW_LINKS)).longValue();
        } catch (IOException | UnsupportedOperationException e) {
            return "has an owner that cannot be read (" + e + ")";
        }
        if (owner != uid) {
            return "belongs to uid " + owner + ", not to the runtime's uid " + uid;
        }
        Set<PosixFilePermission> open = EnumSet.noneOf(PosixFilePermission.class);
        open.addAll(a.permissions());
        open.retainAll(OPEN);
        if (!open.isEmpty()) {
            return "has mode " + PosixFilePermissions.toString(a.permissions()) + ": group or others may use it (the "
                    + "DRCR writes it 0600)";
        }
        if (a.size() > MAX_BYTES) {
            return "is " + a.size() + " bytes, more than a history can be (" + MAX_BYTES + ")";
        }
        return null;
    }

    private static byte[] readAll(SeekableByteChannel ch) throws IOException {
        ByteBuffer buf = ByteBuffer.allocate((int) Math.min(MAX_BYTES + 1, Math.max(16, ch.size() + 1)));
        while (buf.hasRemaining() && ch.read(buf) >= 0) {
            // read to the end or past the bound
        }
        if (!buf.hasRemaining()) {
            if (buf.capacity() > MAX_BYTES) {
                throw new IOException("more than " + MAX_BYTES + " bytes");
            }
            throw new IOException("it grew while it was read");
        }
        byte[] b = new byte[buf.position()];
        buf.flip().get(b);
        return b;
    }

    /** Logs why the file is refused and moves it aside (never over anything). */
    private void refuse(String why) {
        Path aside = null;
        String moved;
        for (int n = 0; n < 100 && aside == null; n++) {
            Path p = file.resolveSibling(NAME + ".refused-" + STAMP.format(java.time.Instant.now()) + (n == 0 ? "" : "-" + n));
            try {
                // rename(2) of the entry itself: a link is moved as the link; no REPLACE_EXISTING
                Files.move(file, p, LinkOption.NOFOLLOW_LINKS);
                aside = p;
            } catch (FileAlreadyExistsException e) {
                // a name taken: the next one
            } catch (IOException e) {
                blocked = file + " " + why + " and could not be set aside (" + e + ")";
                break;
            }
        }
        if (aside != null) {
            moved = "set aside as " + aside.getFileName();
        } else {
            if (blocked == null) {
                blocked = file + " " + why + " and could not be set aside (no free name)";
            }
            moved = "it could not be set aside, so the history is not written over it";
        }
        log.accept("arflex: change-set history: " + file + " refused: it " + why + "; " + moved
                + "; the history starts empty");
    }

    /** Writes the records whole in place of the file. */
    void write(List<ChangeSetDTO> records) throws IOException {
        String b = blocked;
        if (b != null) {
            throw new IOException(b + ": not written");
        }
        byte[] bytes = HistoryFormat.write(records);
        Files.createDirectories(file.getParent());
        Path tmp = file.resolveSibling(NAME + "." + HexFormat.of().formatHex(randomBytes()) + ".tmp");
        try {
            try (FileChannel ch = FileChannel.open(tmp, Set.of(StandardOpenOption.CREATE_NEW, StandardOpenOption.WRITE,
                    LinkOption.NOFOLLOW_LINKS), PosixFilePermissions.asFileAttribute(PosixFilePermissions.fromString("rw-------")))) {
                ByteBuffer buf = ByteBuffer.wrap(bytes);
                while (buf.hasRemaining()) {
                    ch.write(buf);
                }
                ch.force(true);
            }
            Files.move(tmp, file, StandardCopyOption.ATOMIC_MOVE);
        } catch (IOException e) {
            try {
                Files.deleteIfExists(tmp);
            } catch (IOException ignored) {
                // the next start sweeps it
            }
            throw e;
        }
        try (FileChannel dir = FileChannel.open(file.getParent(), StandardOpenOption.READ)) {
            dir.force(true);
        } catch (IOException ignored) {
            // a folder that cannot be synced: the rename is still atomic, only its durability waits
        }
    }

    private static byte[] randomBytes() {
        byte[] r = new byte[8];
        RANDOM.nextBytes(r);
        return r;
    }

    /** Removes temporary files a write cut short left (regular files or links of the DRCR's name only). */
    private void sweepTemporaries() {
        try (DirectoryStream<Path> ds = Files.newDirectoryStream(file.getParent(), NAME + ".*.tmp")) {
            for (Path p : ds) {
                if (p.getFileName().toString().matches("\\Q" + NAME + "\\E\\.[0-9a-f]{16}\\.tmp")
                        && (Files.isRegularFile(p, LinkOption.NOFOLLOW_LINKS) || Files.isSymbolicLink(p))) {
                    Files.deleteIfExists(p); // unlink(2): a link goes, never its target
                    log.accept("arflex: change-set history: removed " + p + ", left by a write that did not finish");
                }
            }
        } catch (NoSuchFileException e) {
            // no folder yet
        } catch (IOException e) {
            log.accept("arflex: change-set history: temporary files in " + file.getParent() + " not swept: " + e);
        }
    }
}
