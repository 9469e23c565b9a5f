package org.arflex.contract;

/**
 * What the supervisor does when the RT half crashes or hangs, in the style of Erlang/OTP
 * supervisors: at most {@code intensity} restarts in {@code windowMs}, with exponential backoff
 * from {@code backoffMs}; past that the component is Failed.
 *
 * @param restart            restart strategy
 * @param intensity          restarts allowed within the window
 * @param windowMs           the intensity window, milliseconds
 * @param backoffMs          first restart delay, doubled each restart inside the window
 * @param safeOutput         what the RT half's outputs do in safe mode
 * @param heartbeatTimeoutMs how long the RT half tolerates a silent runtime (then it calls its
 *                           safe hook), and the runtime a silent RT half (then it is hung)
 * @param orphanHoldMs       how long an RT half whose supervisor (the runtime) died holds its
 *                           safe outputs before it exits and removes its shared objects
 */
public record FaultPolicy(
        Restart restart, int intensity, long windowMs, long backoffMs, SafeOutput safeOutput, long heartbeatTimeoutMs,
        long orphanHoldMs) {

    /** The default {@code orphanHold}, milliseconds. */
    public static final long DEFAULT_ORPHAN_HOLD_MS = 2_000;

    /** With the default orphan hold. */
    public FaultPolicy(Restart restart, int intensity, long windowMs, long backoffMs, SafeOutput safeOutput,
            long heartbeatTimeoutMs) {
        this(restart, intensity, windowMs, backoffMs, safeOutput, heartbeatTimeoutMs, DEFAULT_ORPHAN_HOLD_MS);
    }

    /** Restart strategy, as OTP child specs. */
    public enum Restart {
        /** Always restart. */
        PERMANENT,
        /** Restart only after an abnormal exit (crash, hang, non-zero exit). */
        TRANSIENT,
        /** Never restart. */
        TEMPORARY
    }

    /** Safe output behaviour. */
    public enum SafeOutput {
        /** Keep the last output value. */
        HOLD,
        /** Write zeros to every output. */
        ZERO
    }
}
