package org.arflex.drcr.impl;

import java.io.IOException;
import java.nio.ByteBuffer;
import java.nio.ByteOrder;
import java.nio.charset.StandardCharsets;
import java.nio.file.DirectoryStream;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.function.Consumer;
import java.util.function.IntPredicate;
import java.util.regex.Matcher;
import java.util.regex.Pattern;
import org.arflex.drcr.impl.abi.ControlBlock;
import org.arflex.drcr.impl.abi.MessageQueue;
import org.arflex.drcr.impl.abi.OwnFile;
import org.arflex.drcr.impl.abi.Posix;
import org.arflex.drcr.impl.supervisor.HalfRecords;

/**
 * Removes what a dead runtime left behind: {@code /dev/shm/arflex.<rid>.*} and the queues of
 * the same instances, for our own runtime id (a previous run that crashed) and for
 * default ids ({@code rt<pid>-<10 hex>}, formerly {@code rt<pid>}) whose JVM is gone.
 *
 * <p>/dev/shm is writable by every user (issue 30, D79): a name there is opened only when it is a
 * regular file of this runtime's user ({@link OwnFile}), so a FIFO, device, directory or symlink
 * never blocks or misleads the sweep; any other non-directory is removed (unlink opens nothing)
 * and said so; a directory is left and said so. A process is signalled only when the runtime's
 * own {@link HalfRecords} name it (pid, start time and owner unchanged): an orphaned RT half of
 * a crashed runtime, never a pid read from a file in /dev/shm.
 */
final class Sweeper {

    private static final Pattern NAME = Pattern.compile("arflex\\.([a-z0-9-]{1,40})\\.([a-z0-9-]{1,40})\\.(.+)");
    /** Default runtime ids, {@code rt<pid>-<10 hex>} and the older {@code rt<pid>}. */
    private static final Pattern DEFAULT_RID = Pattern.compile("rt(\\d+)(-[0-9a-f]{10})?");

    private final Path shm;
    private final Path mqueue;
    private final HalfRecords records;
    private final IntPredicate kill;
    private final Consumer<String> log;

    /**
     * @param shm    the folder of the shared-memory names (/dev/shm)
     * @param mqueue the folder of the queue names (/dev/mqueue; queues go by mq_unlink)
     * @param kill   sends SIGKILL to a pid; false when it failed
     */
    Sweeper(Path shm, Path mqueue, HalfRecords records, IntPredicate kill, Consumer<String> log) {
        this.shm = shm;
        this.mqueue = mqueue;
        this.records = records;
        this.kill = kill;
        this.log = log;
    }

    static boolean stale(String rid, String ownRid) {
        if (rid.equals(ownRid)) {
            return true;
        }
        Matcher m = DEFAULT_RID.matcher(rid);
        return m.matches() && !Files.exists(Path.of("/proc", m.group(1)));
    }

    /** Sweeps /dev/shm and /dev/mqueue with the system's records; returns the names removed. */
    static List<String> sweep(String ownRid, Consumer<String> log) {
        return new Sweeper(Path.of("/dev/shm"), Path.of("/dev/mqueue"), HalfRecords.system(log), pid -> {
            try {
                Posix.LIBC.kill(pid, Posix.SIGKILL);
                return true;
            } catch (com.sun.jna.LastErrorException e) {
                return false;
            }
        }, log).sweep(ownRid);
    }

    /**
     * Sweeps; returns the names removed.
     *
     * @throws IllegalStateException when a live runtime uses our runtime id (nothing is touched)
     */
    List<String> sweep(String ownRid) {
        // First pass: refuse before touching anything when the id belongs to a live runtime.
        for (Path p : list(shm, "arflex." + ownRid + ".*.ctl")) {
            checkOwner(p, ownRid);
        }
        List<HalfRecords.Half> orphans = new ArrayList<>();
        for (HalfRecords.Half h : records.all()) {
            if (!HalfRecords.alive(h)) {
                records.forget(h); // that process is gone: its record can name no one any more
            } else if (stale(h.rid(), ownRid)) {
                long parent = parentOf(h.pid());
                if (h.rid().equals(ownRid) && parent > 1 && parent != ProcessHandle.current().pid() && isJava(parent)) {
                    throw new IdInUse("runtime id '" + ownRid + "' is in use by the live runtime pid " + parent
                            + " (its RT half " + h.instance() + " pid " + h.pid() + "); set another arflex.runtime.id");
                }
                orphans.add(h);
            }
        }
        for (HalfRecords.Half h : orphans) {
            boolean killed = kill.test((int) h.pid());
            log.accept("arflex: " + (killed ? "killed" : "could not kill") + " orphaned RT half " + h.instance() + " pid "
                    + h.pid() + " of runtime " + h.rid() + " (this runtime's record: same pid, start time and owner)");
            records.forget(h);
        }
        List<String> removed = new ArrayList<>();
        List<String[]> instances = new ArrayList<>();
        for (Path p : list(shm, "arflex.*")) {
            Matcher m = NAME.matcher(p.getFileName().toString());
            if (!m.matches() || !stale(m.group(1), ownRid)) {
                continue;
            }
            if (m.group(3).equals("ctl")) {
                instances.add(new String[] {m.group(1), m.group(2)});
            }
            if (remove(p)) {
                removed.add(p.toString());
            }
        }
        for (String[] ri : instances) {
            for (String ch : new String[] {"cmd", "rsp"}) {
                String q = "/arflex." + ri[0] + "." + ri[1] + "." + ch;
                if (MessageQueue.unlinkQuietly(q)) {
                    removed.add("mq " + q);
                }
            }
        }
        if (Files.isDirectory(mqueue)) {
            for (Path p : list(mqueue, "arflex.*")) {
                Matcher m = NAME.matcher(p.getFileName().toString());
                if (m.matches() && stale(m.group(1), ownRid) && MessageQueue.unlinkQuietly("/" + p.getFileName())) {
                    removed.add("mq /" + p.getFileName());
                }
            }
        }
        if (!removed.isEmpty()) {
            log.accept("arflex: swept stale objects of dead runtimes: " + removed);
        }
        return removed;
    }

    private List<Path> list(Path dir, String glob) {
        List<Path> l = new ArrayList<>();
        try (DirectoryStream<Path> ds = Files.newDirectoryStream(dir, glob)) {
            ds.forEach(l::add);
        } catch (IOException e) {
            log.accept("arflex: cannot list " + dir + ": " + e.getMessage());
        }
        return l;
    }

    /**
     * Unlinks a stale name without opening it: ours, or anyone's non-directory (a FIFO, a
     * symlink: unlink touches neither the writer nor the target). A directory is left, logged.
     */
    private boolean remove(Path p) {
        String foreign;
        try {
            foreign = OwnFile.foreign(p);
        } catch (IOException e) {
            return false; // gone meanwhile
        }
        if (foreign != null && foreign.startsWith("a directory")) {
            log.accept("arflex: left " + p + ": " + foreign + ", not a shared-memory object of this runtime's user; "
                    + "a spawn that needs the name moves it aside");
            return false;
        }
        try {
            Files.delete(p);
        } catch (IOException e) {
            log.accept("arflex: cannot remove " + p + (foreign != null ? " (" + foreign + ")" : "") + ": " + e);
            return false;
        }
        if (foreign != null) {
            log.accept("arflex: removed " + p + ": " + foreign + ", not made by this runtime's user; never opened");
        }
        return true;
    }

    /** Another live runtime uses our runtime id. */
    static final class IdInUse extends IllegalStateException {
        private static final long serialVersionUID = 1L;

        IdInUse(String m) {
            super(m);
        }
    }

    /**
     * A control block of our id, written by this user (only such is read), names a live RT half
     * of this user run with our id under another live JVM of this user: that runtime is alive.
     */
    private void checkOwner(Path ctl, String rid) {
        byte[] head;
        try {
            head = OwnFile.read(ctl, 64);
        } catch (IOException e) {
            log.accept("arflex: " + e.getMessage() + " (not taken for a live runtime's control block)");
            return;
        }
        if (head.length < 64) {
            return;
        }
        ByteBuffer b = ByteBuffer.wrap(head).order(ByteOrder.LITTLE_ENDIAN);
        int pid = b.getInt(ControlBlock.OFF_PID);
        if (b.getLong(ControlBlock.OFF_MAGIC) != ControlBlock.MAGIC || pid <= 1
                || HalfRecords.uidOf(pid) != OwnFile.euid()) {
            return;
        }
        String cl;
        try {
            cl = new String(Files.readAllBytes(Path.of("/proc", Integer.toString(pid), "cmdline")), StandardCharsets.UTF_8)
                    .replace('\0', ' ');
        } catch (IOException e) {
            return; // gone
        }
        long parent = parentOf(pid);
        if (cl.contains("--runtime " + rid + " ") && parent > 1 && parent != ProcessHandle.current().pid()
                && isJava(parent) && HalfRecords.uidOf(parent) == OwnFile.euid()) {
            throw new IdInUse("runtime id '" + rid + "' is in use by the live runtime pid " + parent
                    + " (its RT half pid " + pid + "); set another arflex.runtime.id");
        }
    }

    private static long parentOf(long pid) {
        try {
            for (String line : Files.readAllLines(Path.of("/proc", Long.toString(pid), "status"))) {
                if (line.startsWith("PPid:")) {
                    return Long.parseLong(line.substring(5).trim());
                }
            }
        } catch (IOException | RuntimeException e) {
            return 0;
        }
        return 0;
    }

    private static boolean isJava(long pid) {
        try {
            String exe = Files.readSymbolicLink(Path.of("/proc", Long.toString(pid), "exe")).getFileName().toString();
            return exe.equals("java");
        } catch (IOException | RuntimeException e) {
            return false;
        }
    }
}
