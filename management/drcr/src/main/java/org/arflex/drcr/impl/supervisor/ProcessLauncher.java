package org.arflex.drcr.impl.supervisor;

import java.io.BufferedReader;
import java.io.IOException;
import java.io.InputStreamReader;
import java.io.OutputStream;
import java.nio.ByteBuffer;
import java.nio.ByteOrder;
import java.nio.charset.StandardCharsets;
import java.security.SecureRandom;
import java.util.ArrayDeque;
import java.util.Deque;
import java.util.List;
import java.util.Map;
import java.util.concurrent.CompletableFuture;
import java.util.concurrent.TimeUnit;
import java.util.concurrent.locks.LockSupport;
import java.util.function.Consumer;
import org.arflex.drcr.impl.abi.ControlBlock;
import org.arflex.drcr.impl.abi.Mailbox;
import org.arflex.drcr.impl.abi.PortSegment;

/**
 * Spawns RT halves as child processes. The child's stdout and stderr go, line by line, to the
 * log through one reader thread per process ({@code arflex-rt-<instance>}); the last lines are
 * kept for the failure reason.
 *
 * <p>The child's stdin is the supervisor pipe (ABI.md 6.2): this side keeps its write end open
 * for the life of the RT half and closes it only in {@link ProcessRtHalf#cleanup()}, after the
 * process exited or was killed; the control block carries {@code CFG_SUPERVISOR_PIPE}. If this
 * JVM dies, the kernel closes the pipe and every RT half sees EOF at once: it goes safe within a
 * cycle, holds for the contract's orphan hold, then exits and removes its objects itself.
 */
public final class ProcessLauncher implements RtLauncher {

    /** Mailbox call timeout. */
    static final long CALL_TIMEOUT_MS = 2_000;
    /**
     * Deadline of each mailbox command on the way out (UNBIND, STOP, SHUTDOWN): a cooperating
     * half answers within a cycle or two; one that does not is terminated, not waited for.
     */
    public static final long STOP_CALL_TIMEOUT_MS = 250;
    /** How long an RT half that reported FAILED may take to exit by itself before it is killed. */
    private static final long FAILED_EXIT_GRACE_MS = 500;
    private static final SecureRandom RANDOM = new SecureRandom();

    private final Consumer<String> log;
    private final VerifiedExecutables executables;
    private final RebindConfirmer confirmer = new RebindConfirmer();
    private final Map<String, String> environment;

    /**
     * A launcher whose halves get {@link HalfEnvironment} of this process's environment, without
     * the test-hook marker.
     *
     * @param executables every executable is checked against it before it is spawned
     */
    public ProcessLauncher(Consumer<String> log, VerifiedExecutables executables) {
        this(log, executables, HalfEnvironment.of(System.getenv(), false));
    }

    /**
     * @param executables every executable is checked against it before it is spawned
     * @param environment the whole environment of every half ({@link HalfEnvironment}), nothing of this process's own
     */
    public ProcessLauncher(Consumer<String> log, VerifiedExecutables executables, Map<String, String> environment) {
        this.log = log;
        this.executables = executables;
        this.environment = Map.copyOf(environment);
    }

    /** The name of a shared object of an instance. */
    public static String objectName(String rid, String inst, String channel) {
        return "/arflex." + rid + "." + inst + "." + channel;
    }

    @Override
    public Output createOutput(String segmentName, int method, String typeName, int major, int minor, int elemSize,
                               int depth, int overflow) throws IOException {
        PortSegment seg = Squatters.createExclusive(segmentName, List.of(segmentName), List.of(),
                () -> PortSegment.create(segmentName, method, typeName, major, minor, elemSize, depth, overflow), log);
        return new Output() {
            private boolean closed;

            @Override
            public String name() {
                return seg.name();
            }

            @Override
            public synchronized long published() {
                return closed ? 0 : seg.head();
            }

            @Override
            public synchronized String damage() {
                return closed ? null : seg.damage();
            }

            @Override
            public synchronized void close() {
                if (!closed) {
                    closed = true;
                    seg.close();
                }
            }
        };
    }

    /** A fresh, nonzero mailbox token (0 is the token of hosts without a supervisor pipe). */
    static long newToken() {
        long t;
        do {
            t = RANDOM.nextLong();
        } while (t == 0);
        return t;
    }

    /** The token as the first 8 bytes, little endian, on the supervisor pipe (ABI.md 6.2). */
    static void sendToken(OutputStream pipe, long token) {
        try {
            pipe.write(ByteBuffer.allocate(8).order(ByteOrder.LITTLE_ENDIAN).putLong(0, token).array());
            pipe.flush();
        } catch (IOException e) {
            // the half is gone already, or it exits for want of the token: the wait reports it
        }
    }

    @Override
    public RtHalf launch(Spec spec) throws IOException {
        String rid = spec.runtimeId();
        String inst = spec.instance();
        // every spawn, restarts included, runs the bytes recorded when the bundle was started
        String exe = executables.verify(spec.executable()).toString();
        String ctlName = objectName(rid, inst, "ctl");
        ControlBlock ctl = Squatters.createExclusive(inst, List.of(ctlName), List.of(), () -> ControlBlock.create(ctlName,
                spec.config().withSupervisorPipe(), spec.params(), spec.resetRequired()), log);
        long token = newToken();
        Mailbox mb;
        try {
            String cmd = objectName(rid, inst, "cmd");
            String rsp = objectName(rid, inst, "rsp");
            mb = Squatters.createExclusive(inst, List.of(), List.of(cmd, rsp), () -> Mailbox.create(cmd, rsp, token), log);
        } catch (IOException e) {
            ctl.close();
            throw e;
        }
        Process p;
        try {
            ProcessBuilder pb = new ProcessBuilder(exe, "--runtime", rid, "--instance", inst)
                    .redirectErrorStream(true)
                    .redirectInput(ProcessBuilder.Redirect.PIPE);
            pb.environment().clear(); // not the runtime's: no console password, no stray fault (D80)
            pb.environment().putAll(environment);
            p = pb.start();
        } catch (IOException e) {
            mb.close();
            ctl.close();
            throw new IOException("cannot spawn " + spec.executable() + ": " + e.getMessage(), e);
        }
        // p.getOutputStream() is the supervisor pipe: held open until cleanup(); its first 8
        // bytes are the token (a half that died at once is reported by the wait below)
        mb.watch(p::isAlive); // a call to a half that has exited ends at once, not at its timeout
        ProcessRtHalf half = new ProcessRtHalf(inst, p, ctl, mb, p.getOutputStream(), confirmer);
        sendToken(p.getOutputStream(), token);
        half.pumpOutput(log);
        // Wait for READY (or a failure) with a deadline; the RT half attaches, configures and
        // declares its ports in between.
        long deadline = System.nanoTime() + spec.readyTimeoutMs() * 1_000_000L;
        while (true) {
            int st = ctl.state();
            if (st == ControlBlock.STATE_READY) {
                return half;
            }
            if (st == ControlBlock.STATE_FAILED || !p.isAlive() || System.nanoTime() - deadline > 0) {
                String why = !p.isAlive() ? "exited with status " + exitOf(p)
                        : st == ControlBlock.STATE_FAILED ? "reported FAILED" : "not READY within " + spec.readyTimeoutMs() + " ms";
                int err = ctl.exitStatus();
                try {
                    // The RT half prints why (a program file's file:line, say) before it sets
                    // FAILED and exits. A kill closes the output pipe with whatever the pump
                    // has not read yet, so one that failed is given a moment to exit by itself
                    // and its output is read to the end first.
                    if (st == ControlBlock.STATE_FAILED || !p.isAlive()) {
                        p.waitFor(FAILED_EXIT_GRACE_MS, TimeUnit.MILLISECONDS);
                        if (!p.isAlive()) {
                            half.awaitOutput(1000);
                        }
                    }
                    half.kill();
                    p.waitFor(2, TimeUnit.SECONDS);
                } catch (InterruptedException e) {
                    half.kill();
                    Thread.currentThread().interrupt();
                }
                half.cleanup();
                throw new IOException("RT half " + inst + " " + why + (err != 0 ? ", error " + err : "")
                        + " (state " + ControlBlock.stateName(st) + ")" + half.tailText());
            }
            LockSupport.parkNanos(500_000);
        }
    }

    private static String exitOf(Process p) {
        try {
            return Integer.toString(p.exitValue());
        } catch (IllegalThreadStateException e) {
            return "?";
        }
    }

    /** Describes an exit status as the JVM reports it (128+n for signal n). */
    static RtHalf.Exit describe(int status, boolean requested) {
        long seen = System.nanoTime();
        if (status > 128 && status < 160) {
            return new RtHalf.Exit(status, true, "killed by signal " + (status - 128), requested, seen);
        }
        if (status == 0) {
            return new RtHalf.Exit(0, false, requested ? "exited normally after SHUTDOWN" : "exited with status 0",
                    requested, seen);
        }
        return new RtHalf.Exit(status, true, "exited with status " + status, requested, seen);
    }


    /** What a refused ADOPT's errno means (D41, D57: the half's own log line says the details). */
    static String adoptRefusal(int e) {
        return switch (e) {
            case 95 -> " (EOPNOTSUPP: its executable has no adopt hook)";
            case 74 -> " (EBADMSG: what the old half hands over does not check; the new half's log says what)";
            case 61 -> " (ENODATA: what the old half hands over is incomplete; the new half's log says what)";
            case 1 -> " (EPERM: a file the hand-over needs is not safe to read; the new half's log says which)";
            case 2 -> " (ENOENT: a file the hand-over needs is missing; the new half's log says which)";
            case 91 -> " (EPROTOTYPE: a state block it cannot take)";
            default -> "";
        };
    }

    /** What a READOPT's refusal means (D61). */
    static String readoptRefusal(int e) {
        return switch (e) {
            case 95 -> " (EOPNOTSUPP: its executable has no re-adopt hook, arflex_component_readopt)";
            case 107 -> " (ENOTCONN: it is not running)";
            case 61 -> " (ENODATA: the old half has published no state)";
            case 110 -> " (ETIMEDOUT: its RT thread did not reach a cycle boundary in time)";
            case 91 -> " (EPROTOTYPE: a state block it cannot take)";
            case 22 -> " (EINVAL: a state it does not accept; the new half's log says what)";
            case 2 -> " (ENOENT: the old half's state segment is gone)";
            default -> adoptRefusal(e);
        };
    }

    static String errnoName(int e) {
        return switch (e) {
            case 1 -> "EPERM: not mutable while running";
            case 22 -> "EINVAL: invalid value";
            case 34 -> "ERANGE: out of range";
            case 2 -> "ENOENT: no such parameter";
            case 11 -> "EAGAIN";
            default -> "errno " + e;
        };
    }
}
