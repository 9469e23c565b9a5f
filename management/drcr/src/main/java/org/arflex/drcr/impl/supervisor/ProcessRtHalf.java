package org.arflex.drcr.impl.supervisor;

import java.io.BufferedReader;
import java.io.IOException;
import java.io.InputStreamReader;
import java.io.OutputStream;
import java.nio.ByteBuffer;
import java.nio.ByteOrder;
import java.nio.charset.StandardCharsets;
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
 * One RT half spawned by {@link ProcessLauncher}: its process, control block, mailbox and
 * supervisor pipe; the mailbox commands the DRCR sends it, its exit and its cleanup.
 */
final class ProcessRtHalf implements RtHalf {
    /** Lines of the half's output kept for a failure reason. */
    private static final int TAIL_LINES = 8;
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
            exit.complete(ProcessLauncher.describe(status, stopping));
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
        Mailbox.Reply r = mb.call(c, ProcessLauncher.CALL_TIMEOUT_MS);
        if (r.status() != 0) {
            throw new IOException(c + " refused by " + inst + ": status " + r.status());
        }
        return r;
    }

    @Override
    public void bind(String port, String segment) throws IOException {
        Mailbox.Reply r = mb.bind(port, segment, ProcessLauncher.CALL_TIMEOUT_MS);
        if (r.status() != 0) {
            throw new IOException("BIND " + inst + "." + port + " to " + segment + " refused: status " + r.status());
        }
    }

    @Override
    public void unbind(String port) throws IOException {
        unbind(port, ProcessLauncher.CALL_TIMEOUT_MS);
    }

    @Override
    public void adopt(String stateSegment) throws IOException {
        Mailbox.Reply r = mb.adopt(stateSegment, ProcessLauncher.CALL_TIMEOUT_MS);
        if (r.status() != 0) {
            throw new IOException("ADOPT of " + stateSegment + " refused by " + inst + ": status " + r.status()
                    + ProcessLauncher.adoptRefusal(-r.status()));
        }
    }

    @Override
    public void readopt(String stateSegment) throws IOException {
        // the half answers once its RT thread took it (within a second and two periods)
        Mailbox.Reply r = mb.readopt(stateSegment, ProcessLauncher.CALL_TIMEOUT_MS);
        if (r.status() != 0) {
            throw new IOException("READOPT of " + stateSegment + " refused by " + inst + ": status " + r.status()
                    + ProcessLauncher.readoptRefusal(-r.status()));
        }
    }

    @Override
    public CompletableFuture<Void> rebind(String port, String segment, long waitMs) {
        return confirmer.rebind(mb, inst, port, segment, waitMs, ProcessLauncher.CALL_TIMEOUT_MS);
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
        Mailbox.Reply r = mb.setParam(index, bits, ProcessLauncher.CALL_TIMEOUT_MS);
        if (r.status() != 0) {
            throw new IOException("SET_PARAM refused by " + inst + ": status " + r.status() + " ("
                    + ProcessLauncher.errnoName(-r.status()) + ")");
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
     * ABI.md 6.1: STOP and SHUTDOWN (each within {@link ProcessLauncher#STOP_CALL_TIMEOUT_MS}); a half that
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
                long callMs = Math.max(1, Math.min(ProcessLauncher.STOP_CALL_TIMEOUT_MS, deadlineMs));
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
