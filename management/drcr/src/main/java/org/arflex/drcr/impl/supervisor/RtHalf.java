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
     * Orderly end: STOP, SHUTDOWN, wait for the exit until {@code deadlineMs}, SIGKILL if it is
     * still there, then remove the control block and queues. Never throws; idempotent.
     */
    void shutdown(long deadlineMs);

    /** SIGKILL now (hang), without waiting; the exit future completes when it is gone. */
    void kill();

    /** Removes the control block and the queues (after the exit). Idempotent. */
    void cleanup();

    /** How a process ended. */
    record Exit(int status, boolean abnormal, String description) {
    }
}
