package org.arflex.it;

import java.io.IOException;
import java.nio.ByteBuffer;
import java.nio.ByteOrder;
import java.nio.charset.StandardCharsets;
import java.nio.file.DirectoryStream;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.Map;
import java.util.concurrent.TimeUnit;

/**
 * Names in /dev/shm as doors (issue 30 findings 2, 3 and 4, docs/decisions/D79): a second local
 * user, created here and removed in {@link #close()}, puts a FIFO, a forged control block or a
 * directory under the names the runtime sweeps or creates. An attempt <em>succeeded</em> when
 * the runtime did not come up or stop in time, refused its id, signalled the attacker's
 * process, or could not restart a component. Used by ShmDoorsIT and the attack benchmark.
 */
final class ShmDoors implements AutoCloseable {

    /** A runtime id of the default form whose JVM is not running: every sweep takes its names. */
    static final String STALE = "rt99999-0000000000";
    /** struct arflex_ctl (rt-core/include/arflex/control.h): magic "ARFLXCTL" at 0, pid at 32. */
    private static final long CTL_MAGIC = 0x4c5443584c465241L;
    private static final int OFF_PID = 32;

    final List<CodeDoors.Attempt> attempts = new ArrayList<>();
    private final String user = "arflex-atk-" + ProcessHandle.current().pid();
    private final int uid;
    private final int gid;
    private final List<Process> processes = new ArrayList<>();
    private final List<Path> planted = new ArrayList<>();

    ShmDoors() throws IOException, InterruptedException {
        run("useradd", "--system", "--no-create-home", "--shell", "/usr/sbin/nologin", user);
        uid = Integer.parseInt(run("id", "-u", user).strip());
        gid = Integer.parseInt(run("id", "-g", user).strip());
    }

    private static String run(String... cmd) throws IOException, InterruptedException {
        Process p = new ProcessBuilder(cmd).redirectErrorStream(true).start();
        String out = new String(p.getInputStream().readAllBytes(), StandardCharsets.UTF_8);
        if (!p.waitFor(30, TimeUnit.SECONDS) || p.exitValue() != 0) {
            throw new IOException(String.join(" ", cmd) + " failed: " + out);
        }
        return out;
    }

    /** The command run as the attacker (no groups, no capabilities). */
    private List<String> as(String... cmd) {
        List<String> l = new ArrayList<>(List.of("setpriv", "--reuid=" + uid, "--regid=" + gid, "--clear-groups"));
        l.addAll(List.of(cmd));
        return l;
    }

    private String runAs(String... cmd) throws IOException, InterruptedException {
        return run(as(cmd).toArray(String[]::new));
    }

    /** A process of the attacker's that stays, its command line holding {@code --runtime STALE}. */
    private Process lookalike(boolean javaParent) throws IOException {
        Process p = javaParent
                // a child of this JVM: its parent is a java, as a runtime's RT half's is
                ? new ProcessBuilder(as("sh", "-c", "sleep 300; :", "x", "--runtime", STALE, "--instance", "x")).start()
                : new ProcessBuilder(as("sh", "-c", "sh -c 'sleep 300; :' x --runtime " + STALE + " --instance x & echo $!; wait"))
                        .start();
        processes.add(p);
        return p;
    }

    private Path shm(String name) {
        Path p = Path.of("/dev/shm", name);
        planted.add(p);
        return p;
    }

    /** Finding 2: a FIFO at a stale control block's name, made before the runtime starts and while it runs. */
    void tryFifo() throws Exception {
        Path fifo = shm("arflex." + STALE + ".x.ctl");
        runAs("mkfifo", fifo.toString());
        long t0 = System.nanoTime();
        boolean up;
        try (Runtime rt = new Runtime("shm-fifo", null, false, "bundle,cell,tools")) {
            up = await(() -> rt.cmd("arflex:dto", 5).startsWith("{"), 30_000);
            long startMs = (System.nanoTime() - t0) / 1_000_000;
            attempts.add(new CodeDoors.Attempt("FIFO at /dev/shm/arflex.<stale rid>.x.ctl before start", !up,
                    up ? "the DRCR answered after " + startMs + " ms" : "the DRCR did not come up within 30 s: " + last(rt)));
            Files.deleteIfExists(fifo);
            runAs("mkfifo", fifo.toString());
            t0 = System.nanoTime();
        } catch (AssertionError e) {
            // close() gives up after 60 s and says so
            attempts.add(new CodeDoors.Attempt("FIFO at /dev/shm/arflex.<stale rid>.x.ctl at stop 0", true,
                    "stop 0 did not end: " + firstLine(e.getMessage())));
            return;
        }
        long stopMs = (System.nanoTime() - t0) / 1_000_000;
        attempts.add(new CodeDoors.Attempt("FIFO at /dev/shm/arflex.<stale rid>.x.ctl at stop 0", stopMs > 15_000,
                "stop 0 took " + stopMs + " ms; FIFO " + (Files.exists(fifo) ? "still there" : "removed")));
    }

    /**
     * Finding 3: a 64-byte control block of the attacker's with the magic and the pid of the
     * attacker's process whose command line holds {@code --runtime STALE}: with a java parent it
     * made the DRCR refuse to start, with any other the sweep sent it SIGKILL as root.
     */
    void tryForgedControlBlock(boolean javaParent) throws Exception {
        Process p = lookalike(javaParent);
        long pid = javaParent ? p.pid() : Long.parseLong(firstLine(new String(readLine(p), StandardCharsets.US_ASCII)));
        Path ctl = shm("arflex." + STALE + ".x.ctl");
        ByteBuffer b = ByteBuffer.allocate(64).order(ByteOrder.LITTLE_ENDIAN);
        b.putLong(0, CTL_MAGIC).putInt(OFF_PID, (int) pid);
        Files.write(ctl, b.array());
        Files.setOwner(ctl, ctl.getFileSystem().getUserPrincipalLookupService().lookupPrincipalByName(user));
        String door = "forged control block naming the attacker's pid (" + (javaParent ? "java parent" : "shell parent") + ")";
        try (Runtime rt = new Runtime("shm-forged", null, false, "bundle,cell,tools")) {
            boolean up = await(() -> rt.cmd("arflex:dto", 5).startsWith("{") || rt.logContains("is in use"), 60_000)
                    && rt.cmd("arflex:dto", 5).startsWith("{");
            boolean killed = !ProcessHandle.of(pid).map(ProcessHandle::isAlive).orElse(false);
            attempts.add(new CodeDoors.Attempt(door, !up || killed, (up ? "the DRCR came up" : "the DRCR refused: " + last(rt))
                    + "; attacker's pid " + pid + (killed ? " KILLED by the sweep" : " alive")
                    + "; forged file " + (Files.exists(ctl) ? "still there" : "removed")));
        }
        end(p);
    }

    /** Ends an attacker's process and everything it started, and waits for them. */
    private static void end(Process p) {
        List<ProcessHandle> all = new ArrayList<>(p.descendants().toList());
        all.add(p.toHandle());
        all.forEach(ProcessHandle::destroyForcibly);
        all.forEach(h -> h.onExit().orTimeout(10, TimeUnit.SECONDS).exceptionally(e -> h).join());
    }

    private static byte[] readLine(Process p) throws IOException {
        java.io.ByteArrayOutputStream o = new java.io.ByteArrayOutputStream();
        int c;
        while ((c = p.getInputStream().read()) >= 0 && c != '\n') {
            o.write(c);
        }
        return o.toByteArray();
    }

    /**
     * Finding 4: a directory at the component's control block name while it is stopped (Felix
     * {@code stop}) or right after its RT half crashed: shm_unlink cannot remove a directory,
     * so every spawn failed until the component went FAILED.
     */
    void trySquattedDirectory(Runtime rt, long bundle) throws Exception {
        String comp = CodeDoors.COMPONENT;
        Path ctl = shm("arflex." + rt.rid + "." + comp + ".ctl");
        rt.cmd("stop " + bundle);
        // Felix stop removes the process and its objects; the component shows INSTALLED
        rt.waitUntil(comp + " stopped", CellIT.T, () -> "INSTALLED".equals(rt.state(comp)) && rt.pid(comp) == 0);
        runAs("mkdir", ctl.toString());
        runAs("touch", ctl.resolve("mine").toString());
        rt.cmd("start " + bundle);
        boolean active = await(() -> "ACTIVE".equals(rt.state(comp)), 20_000);
        attempts.add(new CodeDoors.Attempt("directory at the stopped component's .ctl name", !active, describe(rt, comp)));
        if (!active) {
            return;
        }
        // right after a crash: the attacker's mkdir spins until the name is free, then holds it
        long pid = rt.pid(comp);
        Process squat = new ProcessBuilder(as("timeout", "20", "sh", "-c",
                "until mkdir " + ctl + " 2>/dev/null; do :; done")).start();
        processes.add(squat);
        ProcessHandle.of(pid).ifPresent(ProcessHandle::destroyForcibly);
        boolean squatted = squat.waitFor(25, TimeUnit.SECONDS) && squat.exitValue() == 0;
        boolean back = await(() -> rt.activeWithNewPid(comp, pid), 30_000);
        attempts.add(new CodeDoors.Attempt("directory at the .ctl name right after the RT half crashed", !back,
                (squatted ? "squatted in the gap; " : "the restart won the race (no squat); ") + describe(rt, comp)));
    }

    /** Every door: three runtimes of its own, then the squat against {@code rt} with the component from {@code jar}. */
    void tryAll(Runtime rt, Path jar) throws Exception {
        tryFifo();
        tryForgedControlBlock(true);
        tryForgedControlBlock(false);
        long id = rt.installAndStart(jar);
        rt.awaitState("ACTIVE", CellIT.T, CodeDoors.COMPONENT);
        trySquattedDirectory(rt, id);
        rt.cmd("uninstall " + id);
        rt.waitUntil(CodeDoors.COMPONENT + " gone", CellIT.T, () -> rt.instance(CodeDoors.COMPONENT) == null);
    }

    private static String describe(Runtime rt, String comp) {
        Map<String, Object> i = rt.instance(comp);
        return i == null ? "no instance" : i.get("state") + (i.get("reason") == null ? "" : " " + i.get("reason"))
                + ", restarts " + i.get("restarts");
    }

    /** What the runtime said last about arflex or the sweep. */
    private static String last(Runtime rt) {
        String t = rt.tail();
        int i = Math.max(t.lastIndexOf("is in use"), t.lastIndexOf("swept"));
        return i < 0 ? firstLine(t.substring(Math.max(0, t.length() - 200))) : firstLine(t.substring(Math.max(0, i - 100)));
    }

    private static String firstLine(String s) {
        int i = s.indexOf('\n');
        return (i < 0 ? s : s.substring(0, i)).strip();
    }

    interface Cond {
        boolean holds() throws Exception;
    }

    /** Whether {@code c} holds within {@code ms} (looked at every 200 ms). */
    static boolean await(Cond c, long ms) throws Exception {
        long deadline = System.nanoTime() + ms * 1_000_000L;
        while (true) {
            try {
                if (c.holds()) {
                    return true;
                }
            } catch (AssertionError e) {
                // a command that did not answer in time: not yet
            }
            if (System.nanoTime() - deadline > 0) {
                return false;
            }
            Thread.sleep(200);
        }
    }

    /** Removes what was planted (and what the runtime moved aside), the attacker's processes, then the user. */
    @Override
    public void close() throws Exception {
        processes.forEach(ShmDoors::end);
        // what the attacker's processes left when something killed their parent (the old sweep did)
        List<ProcessHandle> left = ProcessHandle.allProcesses()
                .filter(h -> h.info().user().map(user::equals).orElse(false)).toList();
        left.forEach(ProcessHandle::destroyForcibly);
        left.forEach(h -> h.onExit().orTimeout(10, TimeUnit.SECONDS).exceptionally(e -> h).join());
        List<Path> all = new ArrayList<>(planted);
        try (DirectoryStream<Path> ds = Files.newDirectoryStream(Path.of("/dev/shm"), "squatted.arflex.*")) {
            ds.forEach(all::add);
        }
        for (Path p : all) {
            if (Files.isDirectory(p, java.nio.file.LinkOption.NOFOLLOW_LINKS)) {
                Runtime.deleteTree(p);
            } else {
                Files.deleteIfExists(p);
            }
        }
        run("userdel", user);
    }
}
