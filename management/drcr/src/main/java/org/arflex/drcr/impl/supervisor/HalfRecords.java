package org.arflex.drcr.impl.supervisor;

import java.io.IOException;
import java.nio.charset.StandardCharsets;
import java.nio.file.DirectoryStream;
import java.nio.file.Files;
import java.nio.file.LinkOption;
import java.nio.file.Path;
import java.nio.file.attribute.PosixFileAttributes;
import java.nio.file.attribute.PosixFilePermission;
import java.nio.file.attribute.PosixFilePermissions;
import java.util.ArrayList;
import java.util.List;
import java.util.function.Consumer;
import java.util.regex.Matcher;
import java.util.regex.Pattern;
import org.arflex.drcr.impl.abi.OwnFile;

/**
 * The runtime's own record of the RT halves it spawned (issue 30 finding 3, D79): one file
 * {@code <rid>.<instance>.<pid>} per living half, holding the pid and its start time (field 22
 * of /proc/pid/stat, clock ticks since boot), in a folder only this user can write
 * ({@code /run/arflex} for root, mode 0700). The sweep signals a process only when a record
 * names it and its start time and owner are still those recorded: never a pid read from a file
 * in /dev/shm, never a process found by its command line, never a reused pid.
 */
public final class HalfRecords {

    private static final Pattern FILE = Pattern.compile("([a-z0-9-]{1,40})\\.([a-z0-9-]{1,40})\\.(\\d{1,10})");

    /** One spawned half. */
    public record Half(String rid, String instance, long pid, long startTime, Path file) {
    }

    private final Path dir;
    private final Consumer<String> log;

    public HalfRecords(Path dir, Consumer<String> log) {
        this.dir = dir;
        this.log = log;
    }

    /** The folder for this user: /run/arflex for root, else {@code <tmpdir>/arflex-<uid>}. */
    public static HalfRecords system(Consumer<String> log) {
        int uid = OwnFile.euid();
        Path d = uid == 0 ? Path.of("/run/arflex") : Path.of(System.getProperty("java.io.tmpdir"), "arflex-" + uid);
        return new HalfRecords(d, log);
    }

    public Path dir() {
        return dir;
    }

    /**
     * Null when the folder is a directory of this user's that no one else can write (created so
     * when missing), else why it cannot hold records.
     */
    String unusable() {
        try {
            if (!Files.exists(dir, LinkOption.NOFOLLOW_LINKS)) {
                Files.createDirectories(dir.getParent());
                Files.createDirectory(dir, PosixFilePermissions.asFileAttribute(PosixFilePermissions.fromString("rwx------")));
            }
            PosixFileAttributes a = Files.readAttributes(dir, PosixFileAttributes.class, LinkOption.NOFOLLOW_LINKS);
            int uid = (Integer) Files.getAttribute(dir, "unix:uid", LinkOption.NOFOLLOW_LINKS);
            if (!a.isDirectory() || uid != OwnFile.euid() || a.permissions().contains(PosixFilePermission.GROUP_WRITE)
                    || a.permissions().contains(PosixFilePermission.OTHERS_WRITE)) {
                return dir + " is " + (a.isDirectory() ? "a directory" : a.isSymbolicLink() ? "a symlink" : "not a directory")
                        + " owned by uid " + uid + ", mode " + PosixFilePermissions.toString(a.permissions())
                        + " (must be this user's, uid " + OwnFile.euid() + ", writable by no one else)";
            }
            return null;
        } catch (IOException | RuntimeException e) {
            return dir + ": " + e;
        }
    }

    /** Records a half just spawned; a failure is logged (the half runs unrecorded: no sweep signals it). */
    public void spawned(String rid, String inst, long pid) {
        String why = unusable();
        long start = startTime(pid);
        if (why != null || start < 0) {
            log.accept("arflex: RT half " + inst + " pid " + pid + " not recorded (a later sweep will not signal it): "
                    + (why != null ? why : "/proc/" + pid + "/stat unreadable"));
            return;
        }
        Path f = dir.resolve(rid + "." + inst + "." + pid);
        try {
            Files.deleteIfExists(f);
            Files.createFile(f, PosixFilePermissions.asFileAttribute(PosixFilePermissions.fromString("rw-------")));
            Files.writeString(f, pid + " " + start + "\n");
        } catch (IOException e) {
            log.accept("arflex: RT half " + inst + " pid " + pid + " not recorded in " + f + ": " + e);
        }
    }

    /** Removes the record of a half that was reaped. */
    public void exited(String rid, String inst, long pid) {
        try {
            Files.deleteIfExists(dir.resolve(rid + "." + inst + "." + pid));
        } catch (IOException e) {
            log.accept("arflex: record of RT half " + inst + " pid " + pid + " not removed: " + e);
        }
    }

    /** Every record in the folder (none when the folder is not safe to read: logged). */
    public List<Half> all() {
        List<Half> l = new ArrayList<>();
        if (!Files.isDirectory(dir, LinkOption.NOFOLLOW_LINKS)) {
            return l;
        }
        String why = unusable();
        if (why != null) {
            log.accept("arflex: records of spawned RT halves not read, nothing is signalled: " + why);
            return l;
        }
        try (DirectoryStream<Path> ds = Files.newDirectoryStream(dir)) {
            for (Path f : ds) {
                Matcher m = FILE.matcher(f.getFileName().toString());
                if (!m.matches()) {
                    continue;
                }
                try {
                    String[] v = new String(OwnFile.read(f, 64), StandardCharsets.US_ASCII).trim().split(" ");
                    if (v.length == 2 && Long.parseLong(v[0]) == Long.parseLong(m.group(3))) {
                        l.add(new Half(m.group(1), m.group(2), Long.parseLong(v[0]), Long.parseLong(v[1]), f));
                    }
                } catch (IOException | NumberFormatException e) {
                    log.accept("arflex: record " + f + " not read: " + e.getMessage());
                }
            }
        } catch (IOException e) {
            log.accept("arflex: cannot list " + dir + ": " + e);
        }
        return l;
    }

    /** Whether the recorded process is still that process: same start time, same owner. */
    public static boolean alive(Half h) {
        return h.pid() > 1 && startTime(h.pid()) == h.startTime() && uidOf(h.pid()) == OwnFile.euid();
    }

    /** Field 22 of /proc/pid/stat (start time in clock ticks after boot), -1 when unreadable. */
    public static long startTime(long pid) {
        try {
            String s = Files.readString(Path.of("/proc", Long.toString(pid), "stat"));
            // the command (field 2) may hold spaces and parentheses: count from the last ')'
            String[] f = s.substring(s.lastIndexOf(')') + 2).split(" ");
            return Long.parseLong(f[19]);
        } catch (IOException | RuntimeException e) {
            return -1;
        }
    }

    /** The real uid of a process (first value of Uid: in /proc/pid/status), -1 when unknown. */
    public static int uidOf(long pid) {
        try {
            for (String line : Files.readAllLines(Path.of("/proc", Long.toString(pid), "status"))) {
                if (line.startsWith("Uid:")) {
                    return Integer.parseInt(line.substring(4).trim().split("\\s+")[0]);
                }
            }
        } catch (IOException | RuntimeException e) {
            return -1;
        }
        return -1;
    }

    /** Removes one record. */
    public void forget(Half h) {
        exited(h.rid(), h.instance(), h.pid());
    }
}
