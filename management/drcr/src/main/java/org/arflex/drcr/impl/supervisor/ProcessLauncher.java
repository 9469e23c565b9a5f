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
    private static final int TAIL_LINES = 8;
    /** How long an RT half that reported FAILED may take to exit by itself before it is killed. */
    private static final long FAILED_EXIT_GRACE_MS = 500;
    private static final SecureRandom RANDOM = new SecureRandom();

    private final Consumer<String> log;
    private final VerifiedExecutables executables;
    private final RebindConfirmer confirmer = new RebindConfirmer();

    /** @param executables every executable is checked against it before it is spawned */
    public ProcessLauncher(Consumer<String> log, VerifiedExecutables executables) {
        this.log = log;
        this.executables = executables;
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

    static final class ProcessRtHalf implements RtHalf {
        private final String inst;
        private final Process process;
        private final ControlBlock ctl;
        private final Mailbox mb;
        private final OutputStream supervisorPipe;
        private final RebindConfirmer confirmer;
        private final Deque<String> tail = new ArrayDeque<>();
        private Thread pump;
        private final CompletableFuture<Exit> exit;
        private volatile boolean stopping;
        // Guards the mapping: readers on the heartbeat thread must never touch an unmapped
        // control block, so every ctl access and the cleanup hold this object's lock.
        private boolean cleaned;

        ProcessRtHalf(String inst, Process process, ControlBlock ctl, Mailbox mb, OutputStream supervisorPipe,
                      RebindConfirmer confirmer) {
            this.inst = inst;
            this.process = process;
            this.ctl = ctl;
            this.mb = mb;
            this.supervisorPipe = supervisorPipe;
            this.confirmer = confirmer;
            this.exit = new CompletableFuture<>();
            // Its own waiter, woken by the JDK's reaper (which waits in waitpid) directly:
            // Process.onExit() would complete on the common fork-join pool (one thread on two
            // cores), so an exit would wait behind whatever else that pool runs.
            Thread waiter = new Thread(() -> {
                int status;
                while (true) {
                    try {
                        status = process.waitFor();
                        break;
                    } catch (InterruptedException e) {
                        // not ours to stop: the process is what ends this thread
                    }
                }
                exit.complete(describe(status, stopping));
            }, "arflex-exit-" + inst);
            waiter.setDaemon(true);
            waiter.start();
        }

        void pumpOutput(Consumer<String> log) {
            Thread t = new Thread(() -> {
                try (BufferedReader r = new BufferedReader(
                        new InputStreamReader(process.getInputStream(), StandardCharsets.UTF_8))) {
                    String line;
                    while ((line = r.readLine()) != null) {
                        synchronized (tail) {
                            tail.addLast(line);
                            if (tail.size() > TAIL_LINES) {
                                tail.removeFirst();
                            }
                        }
                        log.accept("[" + inst + " pid " + process.pid() + "] " + line);
                    }
                } catch (IOException ignored) {
                    // the pipe closes when the process exits
                }
            }, "arflex-rt-" + inst);
            t.setDaemon(true);
            pump = t;
            t.start();
        }

        /** Waits up to {@code ms} for the output pump to reach the end of the pipe (the process exited). */
        void awaitOutput(long ms) throws InterruptedException {
            if (pump != null) {
                pump.join(ms);
            }
        }

        String tailText() {
            synchronized (tail) {
                return tail.isEmpty() ? "" : "; last output: " + String.join(" | ", tail);
            }
        }

        @Override
        public long pid() {
            return process.pid();
        }

        @Override
        public CompletableFuture<Exit> exit() {
            return exit;
        }

        private Mailbox.Reply call(Mailbox.Cmd c) throws IOException {
            Mailbox.Reply r = mb.call(c, CALL_TIMEOUT_MS);
            if (r.status() != 0) {
                throw new IOException(c + " refused by " + inst + ": status " + r.status());
            }
            return r;
        }

        @Override
        public void bind(String port, String segment) throws IOException {
            Mailbox.Reply r = mb.bind(port, segment, CALL_TIMEOUT_MS);
            if (r.status() != 0) {
                throw new IOException("BIND " + inst + "." + port + " to " + segment + " refused: status " + r.status());
            }
        }

        @Override
        public void unbind(String port) throws IOException {
            unbind(port, CALL_TIMEOUT_MS);
        }

        @Override
        public void adopt(String stateSegment) throws IOException {
            Mailbox.Reply r = mb.adopt(stateSegment, CALL_TIMEOUT_MS);
            if (r.status() != 0) {
                throw new IOException("ADOPT of " + stateSegment + " refused by " + inst + ": status " + r.status()
                        + adoptRefusal(-r.status()));
            }
        }

        @Override
        public CompletableFuture<Void> rebind(String port, String segment, long waitMs) {
            return confirmer.rebind(mb, inst, port, segment, waitMs, CALL_TIMEOUT_MS);
        }

        @Override
        public synchronized long cycles() {
            if (cleaned) {
                return -1;
            }
            ControlBlock.Stats s = ctl.stats(0);
            return s == null ? -1 : s.cycles();
        }

        @Override
        public boolean awaitCycles(long since, int n, long timeoutMs) {
            long deadline = System.nanoTime() + timeoutMs * 1_000_000L;
            long first = since;
            while (System.nanoTime() - deadline < 0 && process.isAlive()) {
                synchronized (this) {
                    if (cleaned || ctl.state() != ControlBlock.STATE_RUNNING) {
                        return false;
                    }
                    ControlBlock.Stats s = ctl.stats(0);
                    if (s != null) {
                        if (first < 0) {
                            first = s.cycles();
                        } else if (s.cycles() - first >= n) {
                            return true;
                        }
                    }
                }
                LockSupport.parkNanos(200_000);
            }
            return false;
        }

        @Override
        public void start() throws IOException {
            call(Mailbox.Cmd.START);
        }

        @Override
        public void reset() throws IOException {
            call(Mailbox.Cmd.RESET);
        }

        @Override
        public long setParam(int index, long bits) throws IOException {
            Mailbox.Reply r = mb.setParam(index, bits, CALL_TIMEOUT_MS);
            if (r.status() != 0) {
                throw new IOException("SET_PARAM refused by " + inst + ": status " + r.status() + " ("
                        + errnoName(-r.status()) + ")");
            }
            return r.payloadLong(Mailbox.PARAM_VALUE);
        }

        @Override
        public synchronized long paramValue(int index) {
            if (cleaned) {
                return 0;
            }
            return ctl.paramValue(index);
        }

        @Override
        public synchronized int rtState() {
            if (cleaned) {
                return ControlBlock.STATE_EXITED;
            }
            return ctl.state();
        }

        @Override
        public synchronized int flags() {
            if (cleaned) {
                return 0;
            }
            return ctl.flags();
        }

        @Override
        public synchronized java.util.Map<String, Long> inputRejects(java.util.Collection<String> inputs) {
            if (cleaned) {
                return java.util.Map.of();
            }
            return ctl.inputRejects(inputs);
        }

        @Override
        public synchronized int hold() {
            if (cleaned) {
                return 0;
            }
            return ctl.hold();
        }

        @Override
        public synchronized long forgedRequests() {
            if (cleaned) {
                return 0;
            }
            return ctl.warnings(ControlBlock.WARN_FORGED);
        }

        @Override
        public synchronized long rtHeartbeatNs() {
            if (cleaned) {
                return 0;
            }
            return ctl.rtHeartbeatNs();
        }

        @Override
        public synchronized void runtimeHeartbeat(long nowNs) {
            if (cleaned) {
                return;
            }
            ctl.runtimeHeartbeat(nowNs);
        }

        @Override
        public synchronized ControlBlock.Stats stats(long wcetNs) {
            if (cleaned) {
                return null;
            }
            return ctl.stats(wcetNs);
        }

        @Override
        public synchronized ControlBlock.Detail detail(long wcetNs) {
            if (cleaned) {
                return null;
            }
            return ctl.detail(wcetNs);
        }

        @Override
        public void unbind(String port, long timeoutMs) throws IOException {
            Mailbox.Reply r = mb.unbind(port, timeoutMs);
            if (r.status() != 0) {
                throw new IOException("UNBIND " + inst + "." + port + " refused: status " + r.status());
            }
        }

        /**
         * ABI.md 6.1: STOP and SHUTDOWN (each within {@link #STOP_CALL_TIMEOUT_MS}); a half that
         * answered gets two thirds of the deadline to exit by itself, one that did not is sent
         * SIGTERM at once (the RT half stops and exits cleanly on it, unless it is frozen); SIGKILL
         * when the deadline has passed.
         */
        @Override
        public String shutdown(long deadlineMs, Runnable unanswered) {
            stopping = true;
            long t0 = System.nanoTime();
            String how;
            try {
                if (!process.isAlive()) {
                    how = "had exited";
                } else {
                    long callMs = Math.max(1, Math.min(STOP_CALL_TIMEOUT_MS, deadlineMs));
                    String silent = null;
                    try {
                        if (rtState() == ControlBlock.STATE_RUNNING) {
                            mb.call(Mailbox.Cmd.STOP, callMs);
                        }
                        mb.call(Mailbox.Cmd.SHUTDOWN, callMs);
                    } catch (IOException e) {
                        silent = e.getMessage();
                        unanswered.run();
                    }
                    how = reap(t0, deadlineMs, silent);
                }
            } catch (InterruptedException e) {
                process.destroyForcibly();
                Thread.currentThread().interrupt();
                how = "killed (interrupted while stopping)";
            }
            cleanup();
            return how;
        }

        private String reap(long t0, long deadlineMs, String silent) throws InterruptedException {
            long deadline = t0 + deadlineMs * 1_000_000L;
            if (silent == null && process.waitFor(deadlineMs * 2 / 3, TimeUnit.MILLISECONDS)) {
                return "exited after SHUTDOWN in " + ms(t0) + " ms";
            }
            long termAt = ms(t0);
            process.destroy(); // SIGTERM
            if (process.waitFor(Math.max(0, deadline - System.nanoTime()), TimeUnit.NANOSECONDS)) {
                return "exited on SIGTERM after " + ms(t0) + " ms (" + (silent != null ? silent
                        : "answered SHUTDOWN but had not exited") + ")";
            }
            process.destroyForcibly(); // SIGKILL
            process.waitFor(deadlineMs, TimeUnit.MILLISECONDS);
            return "killed after " + ms(t0) + " ms (" + (silent != null ? silent : "answered SHUTDOWN but did not exit")
                    + "; SIGTERM at " + termAt + " ms did not end it" + (process.isAlive() ? "; still not reaped" : "") + ")";
        }

        private static long ms(long t0) {
            return (System.nanoTime() - t0) / 1_000_000L;
        }

        @Override
        public void kill() {
            process.destroyForcibly();
        }

        /**
         * Removes the objects and closes the supervisor pipe. Callers do so once the process has
         * exited or was killed; one still alive would take the closed pipe as its supervisor's
         * death (hold, then exit and unlink, ABI.md 6.2).
         */
        @Override
        public synchronized void cleanup() {
            if (!cleaned) {
                cleaned = true;
                mb.close();
                ctl.close();
                try {
                    supervisorPipe.close();
                } catch (IOException ignored) {
                    // the child is gone; nothing reads the pipe any more
                }
            }
        }
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
