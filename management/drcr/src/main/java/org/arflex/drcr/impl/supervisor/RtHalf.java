package org.arflex.drcr.impl.supervisor;

import java.io.IOException;
import java.util.concurrent.CompletableFuture;
import org.arflex.drcr.impl.abi.ControlBlock;

/**
 * A running RT half as the DRCR sees it: its process, its control block and its mailbox. Made
 * by an {@link RtLauncher}. Methods that talk to the mailbox block for at most their timeout and
 * are called from the actor thread; the read accessors may be called from any thread.
 */
public interface RtHalf {

    /** Process id. */
    long pid();

    /** Completes with the exit description when the process has exited (crash or not). */
    CompletableFuture<Exit> exit();

    /** BIND input {@code port} to the provider segment {@code segment}. */
    void bind(String port, String segment) throws IOException;

    /** UNBIND input {@code port}. */
    void unbind(String port) throws IOException;

    /**
     * ADOPT (D41): before START, names the state segment of the half this one replaces; the
     * RT half takes its newest value over at START. Refused by a half that cannot adopt.
     */
    default void adopt(String stateSegment) throws IOException {
        throw new IOException("this RT half cannot adopt a state block");
    }

    /**
     * READOPT (D61): a running half takes the newest value of the state segment of the half it
     * replaces again, at its next cycle boundary; returns once it did. Refused (with the reason)
     * by a half that cannot take it while it runs.
     */
    default void readopt(String stateSegment) throws IOException {
        throw new IOException("this RT half cannot re-adopt a state block while it runs");
    }

    /**
     * BIND ({@code segment} not null) or UNBIND of input {@code port} of a running half, waiting
     * at most {@code waitMs} for its answer (D39: the actor does not wait on a process). The
     * stage completes when the half has answered; exceptionally when it refused, did not answer
     * within the call timeout, or exited. This default answers at once (a half that answers in
     * the caller's thread).
     */
    default CompletableFuture<Void> rebind(String port, String segment, long waitMs) {
        try {
            if (segment != null) {
                bind(port, segment);
            } else {
                unbind(port);
            }
            return CompletableFuture.completedFuture(null);
        } catch (IOException | RuntimeException e) {
            return CompletableFuture.failedFuture(e);
        }
    }

    /**
     * UNBIND input {@code port}, answered within {@code timeoutMs} (a stop's short deadline: a
     * half that does not answer is not waited for longer).
     */
    default void unbind(String port, long timeoutMs) throws IOException {
        unbind(port);
    }

    /** Cycles the RT loop has completed so far (from its statistics), or -1 when unknown. */
    long cycles();

    /**
     * Waits until the RT loop completed {@code n} more cycles than {@code since} (a value of
     * {@link #cycles()} read after a change such as an UNBIND; -1: from now), so the change
     * reached the RT thread and its safe behaviour ran; at most {@code timeoutMs}.
     *
     * @return false on timeout or when the half is not running
     */
    boolean awaitCycles(long since, int n, long timeoutMs);

    /** START the RT loop. */
    void start() throws IOException;

    /** Operator RESET (leave safe mode, clear reset-required). */
    void reset() throws IOException;

    /**
     * SET_PARAM of slot {@code index}.
     *
     * @return the value in force after the RT half handled it
     * @throws IOException when the RT half refused it (status) or did not answer
     */
    long setParam(int index, long bits) throws IOException;

    /** The value in force of slot {@code index}, read from the control block. */
    long paramValue(int index);

    /** RT state word (ControlBlock.STATE_*). */
    int rtState();

    /** Control block flags. */
    int flags();

    /**
     * True when the half advertises a re-adopt hook (ControlBlock.FLAG_READOPT, set by its
     * configure before READY, D70): once running it can take a state block again (READOPT, D61).
     */
    default boolean canReadopt() {
        return (flags() & ControlBlock.FLAG_READOPT) != 0;
    }

    /** Rejected values per input in this run (ControlBlock.inputRejects); empty when gone. */
    default java.util.Map<String, Long> inputRejects(java.util.Collection<String> inputs) {
        return java.util.Map.of();
    }

    /** The control block's hold word (ControlBlock.OFF_HOLD); 0 when none or gone. */
    default int hold() {
        return 0;
    }

    /**
     * Mailbox requests the RT half ignored because their token was not its own (ABI.md 6.2:
     * someone else on this machine wrote into its command queue); 0 when gone.
     */
    default long forgedRequests() {
        return 0;
    }

    /** The RT thread's heartbeat, CLOCK_MONOTONIC ns (0 before its first cycle). */
    long rtHeartbeatNs();

    /** Writes the runtime heartbeat into the control block. */
    void runtimeHeartbeat(long nowNs);

    /** Statistics snapshot, or null when the seqlock could not be read. */
    ControlBlock.Stats stats(long wcetNs);

    /**
     * Statistics with the latency and execution-time histograms, from one seqlock read, or null
     * when it could not be read. A half without histograms returns null metrics.
     */
    default ControlBlock.Detail detail(long wcetNs) {
        ControlBlock.Stats s = stats(wcetNs);
        return s == null ? null : new ControlBlock.Detail(s, null, null);
    }

    /**
     * Orderly end: STOP and SHUTDOWN, each with a short deadline; then SIGTERM, and SIGKILL once
     * {@code deadlineMs} have passed since the call; then the control block and queues are
     * removed. Blocks up to about {@code deadlineMs}: never called on the actor thread. Never
     * throws; idempotent.
     *
     * @param unanswered run (on the calling thread) as soon as STOP or SHUTDOWN went unanswered:
     *                   the half is not cooperating and is on its way to being killed
     * @return how it ended, e.g. "exited after SHUTDOWN in 3 ms" or "killed after 3002 ms (no
     *         answer to STOP within 250 ms; SIGTERM at 251 ms did not end it)"
     */
    String shutdown(long deadlineMs, Runnable unanswered);

    /** {@link #shutdown(long, Runnable)} without a listener. */
    default String shutdown(long deadlineMs) {
        return shutdown(deadlineMs, () -> { });
    }

    /** SIGKILL now (hang), without waiting; the exit future completes when it is gone. */
    void kill();

    /** Removes the control block and the queues (after the exit). Idempotent. */
    void cleanup();

    /**
     * How a process ended. {@code requested}: the supervisor had asked it to stop (SHUTDOWN,
     * then KILL after the deadline); {@code seenNanos}: System.nanoTime() when the exit was
     * seen (on the JDK's reaper thread, which waits in waitpid: the kernel's notice, no
     * polling period).
     */
    record Exit(int status, boolean abnormal, String description, boolean requested, long seenNanos) {
        public Exit(int status, boolean abnormal, String description) {
            this(status, abnormal, description, false, System.nanoTime());
        }
    }
}
