package org.arflex.drcr.impl;

import java.io.IOException;
import java.nio.ByteBuffer;
import java.nio.ByteOrder;
import java.nio.channels.FileChannel;
import java.nio.charset.StandardCharsets;
import java.nio.file.DirectoryStream;
import java.nio.file.Files;
import java.nio.file.Path;
import java.nio.file.StandardOpenOption;
import java.util.ArrayList;
import java.util.List;
import java.util.function.Consumer;
import java.util.regex.Matcher;
import java.util.regex.Pattern;
import org.arflex.drcr.impl.abi.ControlBlock;
import org.arflex.drcr.impl.abi.MessageQueue;
import org.arflex.drcr.impl.abi.Posix;
import org.arflex.drcr.impl.abi.ShmSegment;

/**
 * Removes what a dead runtime left behind: {@code /dev/shm/arflex.<rid>.*} and the queues of
 * the same instances, for our own runtime id (a previous run that crashed) and for
 * default ids ({@code rt<pid>-<10 hex>}, formerly {@code rt<pid>}) whose JVM is gone. Orphaned RT halves (pid in a stale control block,
 * still running with {@code --runtime <rid>} on their command line) are killed.
 */
final class Sweeper {

    private static final Pattern NAME = Pattern.compile("arflex\\.([a-z0-9-]{1,40})\\.([a-z0-9-]{1,40})\\.(.+)");
    /** Default runtime ids, {@code rt<pid>-<10 hex>} and the older {@code rt<pid>}. */
    private static final Pattern DEFAULT_RID = Pattern.compile("rt(\\d+)(-[0-9a-f]{10})?");

    private Sweeper() {
    }

    static boolean stale(String rid, String ownRid) {
        if (rid.equals(ownRid)) {
            return true;
        }
        Matcher m = DEFAULT_RID.matcher(rid);
        return m.matches() && !Files.exists(Path.of("/proc", m.group(1)));
    }

    /**
     * Sweeps; returns the names removed.
     *
     * @throws IllegalStateException when a live runtime uses our runtime id (nothing is touched)
     */
    static List<String> sweep(String ownRid, Consumer<String> log) {
        // First pass: refuse before touching anything when the id belongs to a live runtime.
        try (DirectoryStream<Path> ds = Files.newDirectoryStream(Path.of("/dev/shm"), "arflex." + ownRid + ".*.ctl")) {
            for (Path p : ds) {
                checkOwner(p, ownRid);
            }
        } catch (IOException e) {
            log.accept("arflex: cannot list /dev/shm: " + e.getMessage());
        }
        List<String> removed = new ArrayList<>();
        List<String[]> instances = new ArrayList<>();
        try (DirectoryStream<Path> ds = Files.newDirectoryStream(Path.of("/dev/shm"), "arflex.*")) {
            for (Path p : ds) {
                Matcher m = NAME.matcher(p.getFileName().toString());
                if (!m.matches() || !stale(m.group(1), ownRid)) {
                    continue;
                }
                if (m.group(3).equals("ctl")) {
                    killOrphan(p, m.group(1), log);
                    instances.add(new String[] {m.group(1), m.group(2)});
                }
                if (ShmSegment.unlinkQuietly("/" + p.getFileName())) {
                    removed.add("/dev/shm/" + p.getFileName());
                }
            }
        } catch (IOException e) {
            log.accept("arflex: cannot list /dev/shm: " + e.getMessage());
        }
        for (String[] ri : instances) {
            for (String ch : new String[] {"cmd", "rsp"}) {
                String q = "/arflex." + ri[0] + "." + ri[1] + "." + ch;
                if (MessageQueue.unlinkQuietly(q)) {
                    removed.add("mq " + q);
                }
            }
        }
        Path mq = Path.of("/dev/mqueue");
        if (Files.isDirectory(mq)) {
            try (DirectoryStream<Path> ds = Files.newDirectoryStream(mq, "arflex.*")) {
                for (Path p : ds) {
                    Matcher m = NAME.matcher(p.getFileName().toString());
                    if (m.matches() && stale(m.group(1), ownRid) && MessageQueue.unlinkQuietly("/" + p.getFileName())) {
                        removed.add("mq /" + p.getFileName());
                    }
                }
            } catch (IOException e) {
                log.accept("arflex: cannot list /dev/mqueue: " + e.getMessage());
            }
        }
        if (!removed.isEmpty()) {
            log.accept("arflex: swept stale objects of dead runtimes: " + removed);
        }
        return removed;
    }

    /** Another live runtime uses our runtime id. */
    static final class IdInUse extends IllegalStateException {
        private static final long serialVersionUID = 1L;

        IdInUse(String m) {
            super(m);
        }
    }

    private static void checkOwner(Path ctl, String rid) throws IOException {
        try (FileChannel ch = FileChannel.open(ctl, StandardOpenOption.READ)) {
            ByteBuffer b = ByteBuffer.allocate(64).order(ByteOrder.LITTLE_ENDIAN);
            ch.read(b, 0);
            int pid = b.getInt(ControlBlock.OFF_PID);
            Path cmdline = Path.of("/proc", Integer.toString(pid), "cmdline");
            if (pid <= 1 || !Files.exists(cmdline)) {
                return;
            }
            String cl = new String(Files.readAllBytes(cmdline), StandardCharsets.UTF_8).replace('\0', ' ');
            long parent = parentOf(pid);
            if (cl.contains("--runtime " + rid + " ") && parent > 1 && parent != ProcessHandle.current().pid()
                    && isJava(parent)) {
                throw new IdInUse("runtime id '" + rid + "' is in use by the live runtime pid " + parent
                        + " (its RT half pid " + pid + "); set another arflex.runtime.id");
            }
        }
    }

    private static long parentOf(int pid) throws IOException {
        for (String line : Files.readAllLines(Path.of("/proc", Integer.toString(pid), "status"))) {
            if (line.startsWith("PPid:")) {
                return Long.parseLong(line.substring(5).trim());
            }
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

    private static void killOrphan(Path ctl, String rid, Consumer<String> log) {
        try (FileChannel ch = FileChannel.open(ctl, StandardOpenOption.READ)) {
            ByteBuffer b = ByteBuffer.allocate(64).order(ByteOrder.LITTLE_ENDIAN);
            ch.read(b, 0);
            if (b.getLong(ControlBlock.OFF_MAGIC) != ControlBlock.MAGIC) {
                return;
            }
            int pid = b.getInt(ControlBlock.OFF_PID);
            if (pid <= 1) {
                return;
            }
            Path cmdline = Path.of("/proc", Integer.toString(pid), "cmdline");
            if (!Files.exists(cmdline)) {
                return;
            }
            String cl = new String(Files.readAllBytes(cmdline), StandardCharsets.UTF_8).replace('\0', ' ');
            if (cl.contains("--runtime " + rid + " ")) {
                long parent = parentOf(pid);
                if (parent > 1 && parent != ProcessHandle.current().pid() && isJava(parent)) {
                    // its runtime is alive: this id is in use, and nothing of it may be touched
                    throw new IdInUse("runtime id '" + rid + "' is in use by the live runtime pid " + parent
                            + " (its RT half pid " + pid + " runs " + cl.trim() + "); set another arflex.runtime.id");
                }
                Posix.LIBC.kill(pid, Posix.SIGKILL);
                log.accept("arflex: killed orphaned RT half pid " + pid + " (" + cl.trim() + ")");
            }
        } catch (IdInUse e) {
            throw e;
        } catch (IOException | RuntimeException e) {
            log.accept("arflex: cannot inspect " + ctl + ": " + e.getMessage());
        }
    }
}
