package org.arflex.it;

import com.sun.jna.LastErrorException;
import com.sun.jna.Library;
import com.sun.jna.Native;
import java.nio.ByteBuffer;
import java.nio.ByteOrder;
import java.nio.file.Files;
import java.nio.file.Path;
import java.nio.file.attribute.PosixFilePermissions;
import java.security.SecureRandom;
import java.util.ArrayList;
import java.util.List;
import java.util.Locale;
import java.util.Map;

/**
 * The command channel as a door (issue 16 finding 6, docs/DECISIONS.md D13): a process of the
 * same machine writes requests into a running component's command queue (SHUTDOWN, STOP,
 * RESET, SET_PARAM, each three times, then a flood), and squats the names a component is
 * about to create. An attempt <em>succeeded</em> when the component left ACTIVE, was
 * restarted, took the forged parameter, or could not start because of the squatter. Used by
 * the attack benchmark.
 */
final class MailboxDoors {

    /** libc's message queues, as a same-user attacker would use them. */
    interface Mq extends Library {
        Mq C = Native.load("c", Mq.class);

        int mq_open(String name, int oflag) throws LastErrorException;

        int mq_send(int mqd, byte[] msg, long len, int prio) throws LastErrorException;

        int mq_close(int mqd) throws LastErrorException;
    }

    private static final int O_WRONLY = 1;
    private static final int O_NONBLOCK = 04000;
    private static final int EAGAIN = 11;
    private static final int MAGIC = 0x534D4641;
    private static final int CMD_STOP = 2;
    private static final int CMD_SET_PARAM = 3;
    private static final int CMD_RESET = 9;
    private static final int CMD_SHUTDOWN = 10;

    final List<CodeDoors.Attempt> attempts = new ArrayList<>();
    private final Runtime rt;
    private final SecureRandom random = new SecureRandom();

    MailboxDoors(Runtime rt) {
        this.rt = rt;
    }

    /** One forged request: the right magic and ABI, a guessed token. */
    private byte[] forged(int cmd) {
        ByteBuffer b = ByteBuffer.allocate(512).order(ByteOrder.LITTLE_ENDIAN);
        b.putInt(0, MAGIC).putShort(4, (short) 1).putShort(6, (short) 1).putInt(8, random.nextInt());
        b.putShort(12, (short) cmd).putLong(24, random.nextLong());
        if (cmd == CMD_SET_PARAM) {
            // struct arflex_msg_param: index 0 (amplitude), value bits of 777.0
            b.putInt(20, 56).putInt(32, 0).putLong(40, Double.doubleToLongBits(777.0));
        }
        return b.array();
    }

    private long forgedSeen() {
        Map<String, Object> i = rt.instance(CodeDoors.COMPONENT);
        @SuppressWarnings("unchecked")
        Map<String, Object> s = i == null ? null : (Map<String, Object>) i.get("stats");
        return s == null || s.get("forgedRequests") == null ? -1 : ((Number) s.get("forgedRequests")).longValue();
    }

    /** Tries every forged request against the running counter. */
    void tryForged() {
        String q = "/arflex." + rt.rid + "." + CodeDoors.COMPONENT + ".cmd";
        int[][] kinds = {{CMD_SHUTDOWN, 3}, {CMD_STOP, 3}, {CMD_RESET, 3}, {CMD_SET_PARAM, 3}};
        String[] names = {"SHUTDOWN", "STOP", "RESET", "SET_PARAM amplitude=777"};
        for (int k = 0; k < kinds.length; k++) {
            long pid = rt.pid(CodeDoors.COMPONENT);
            long before = forgedSeen();
            int sent = send(q, kinds[k][0], kinds[k][1]);
            long want = before + sent;
            boolean seen = awaitForged(want);
            attempts.add(judge("forged " + names[k] + " x" + kinds[k][1], pid,
                    sent + " sent, " + (seen ? "all counted as forged" : "not all counted as forged (" + forgedSeen() + "/" + want + ")")));
        }
        // A flood: the queue kept full for two seconds, while the DRCR commands the half.
        long pid = rt.pid(CodeDoors.COMPONENT);
        long before = forgedSeen();
        long t0 = System.nanoTime();
        int sent = 0;
        int full = 0;
        String setOut = "";
        while (System.nanoTime() - t0 < 2_000_000_000L) {
            int n = send(q, CMD_SHUTDOWN, 64);
            sent += n;
            full += n < 64 ? 1 : 0;
            if (setOut.isEmpty() && System.nanoTime() - t0 > 1_000_000_000L) {
                setOut = rt.cmd("arflex:set " + CodeDoors.COMPONENT + " frequency 2.0");
            }
        }
        boolean seen = awaitForged(before + sent);
        String value = rt.cmd("arflex:get " + CodeDoors.COMPONENT + " frequency");
        CodeDoors.Attempt a = judge("flood: command queue full for 2 s", pid, String.format(Locale.ROOT,
                "%d sent (queue full %d times), %s; DRCR set during the flood: '%s', frequency now '%s'", sent, full,
                seen ? "all counted as forged" : "counted " + (forgedSeen() - before), setOut.strip(), value.strip()));
        boolean commandLost = !value.contains("2.0");
        attempts.add(new CodeDoors.Attempt(a.door(), a.succeeded() || commandLost,
                a.detail() + (commandLost ? "; the DRCR's own command was lost" : "")));
    }

    /** Sends {@code n} forged requests without blocking; returns how many the queue took. */
    private int send(String q, int cmd, int n) {
        int d = Mq.C.mq_open(q, O_WRONLY | O_NONBLOCK);
        int sent = 0;
        try {
            for (int k = 0; k < n; k++) {
                byte[] m = forged(cmd);
                try {
                    Mq.C.mq_send(d, m, m.length, 0);
                    sent++;
                } catch (LastErrorException e) {
                    if (e.getErrorCode() != EAGAIN) {
                        throw e;
                    }
                    break;
                }
            }
        } finally {
            Mq.C.mq_close(d);
        }
        return sent;
    }

    private boolean awaitForged(long want) {
        try {
            rt.waitUntil("the counter to count the forged requests", 10_000, () -> forgedSeen() >= want);
            return true;
        } catch (AssertionError e) {
            return false;
        }
    }

    private CodeDoors.Attempt judge(String door, long pid, String detail) {
        Map<String, Object> i = rt.instance(CodeDoors.COMPONENT);
        String state = i == null ? "gone" : (String) i.get("state");
        long now = i == null ? 0 : ((Number) i.get("pid")).longValue();
        String amp = rt.cmd("arflex:get " + CodeDoors.COMPONENT + " amplitude");
        boolean ok = "ACTIVE".equals(state) && now == pid && !amp.contains("777");
        return new CodeDoors.Attempt(door, !ok, detail + "; " + state + (now == pid ? ", same process" : ", process " + pid
                + " -> " + now) + ", amplitude " + amp.strip());
    }

    /**
     * Squats the names the counter is about to create (its control block, queues and output
     * segment), as another user would in world-writable /dev/shm and /dev/mqueue, then installs
     * it from {@code jar}. Succeeded when the component cannot become ACTIVE.
     */
    void trySquat(Path jar) throws Exception {
        String base = "arflex." + rt.rid + "." + CodeDoors.COMPONENT;
        List<Path> squat = new ArrayList<>();
        for (String n : new String[] {base + ".ctl", base + ".out.count"}) {
            Path p = Path.of("/dev/shm", n);
            Files.deleteIfExists(p);
            Files.write(p, new byte[4096]);
            Files.setPosixFilePermissions(p, PosixFilePermissions.fromString("rw-rw-rw-"));
            Files.setOwner(p, p.getFileSystem().getUserPrincipalLookupService().lookupPrincipalByName("nobody"));
            squat.add(p);
        }
        long id = rt.installAndStart(jar);
        boolean active;
        try {
            rt.awaitState("ACTIVE", 20_000, CodeDoors.COMPONENT);
            active = true;
        } catch (AssertionError e) {
            active = false;
        }
        Map<String, Object> i = rt.instance(CodeDoors.COMPONENT);
        attempts.add(new CodeDoors.Attempt("squatted /dev/shm names (owner nobody, 0666) before install", !active,
                (i == null ? "no instance" : i.get("state") + " " + (i.get("reason") == null ? "" : i.get("reason")))
                        + "; squatted names now: " + squat.stream().filter(Files::exists).count()));
        rt.cmd("uninstall " + id);
        rt.waitUntil(CodeDoors.COMPONENT + " gone", 30_000, () -> rt.instance(CodeDoors.COMPONENT) == null);
        for (Path p : squat) {
            Files.deleteIfExists(p);
        }
    }
}
