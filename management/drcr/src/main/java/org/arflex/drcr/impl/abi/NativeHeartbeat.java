package org.arflex.drcr.impl.abi;

import com.sun.jna.Library;
import com.sun.jna.Native;
import com.sun.jna.Pointer;
import com.sun.jna.Structure;
import java.nio.file.Path;

/**
 * The runtime heartbeat's native writer (rt-core {@code arflex/beat.h}, DECISIONS.md D17): a
 * thread outside the JVM's control (no safepoint stops it, no Java lock blocks it) writes
 * {@code runtime_hb_ns} into every control block each period while the DRCR's own heartbeat
 * round said it is alive ({@link #alive()}) within a grace time. A stopped or dead JVM still
 * stops the heartbeat at once; a JVM stall shorter than the grace no longer latches a reset in
 * every moving component; a longer one still does.
 *
 * <p>One writer per process. Control blocks register themselves ({@link ControlBlock#create})
 * and unregister before they are unmapped ({@link ControlBlock#close}); both are no-ops while
 * no writer runs (the Java heartbeat round then is the only writer, as before).
 */
public final class NativeHeartbeat {

    /** The library's functions (beat.h). */
    interface Lib extends Library {
        int arflex_beat_start(long periodNs, long graceNs, int fifoPriority);

        void arflex_beat_stop();

        void arflex_beat_java_alive();

        int arflex_beat_add(Pointer ctl);

        int arflex_beat_remove(Pointer ctl);

        void arflex_beat_stats(Stats out);
    }

    /** struct arflex_beat_stats. */
    @Structure.FieldOrder({"rounds", "withheld", "bridged", "maxSilenceNs", "lastSilenceNs", "registered", "fifo",
        "maxGapNs", "lastRoundNs"})
    public static final class Stats extends Structure {
        public long rounds;
        public long withheld;
        public long bridged;
        public long maxSilenceNs;
        public long lastSilenceNs;
        public int registered;
        public int fifo;
        /** The writer's own longest time between two rounds (D75). */
        public long maxGapNs;
        /** CLOCK_MONOTONIC of its last round, 0 before the first. */
        public long lastRoundNs;
    }

    private static final int ETIMEDOUT = 110;
    private static volatile NativeHeartbeat active;

    private final Lib lib;
    private final long graceMs;

    private NativeHeartbeat(Lib lib, long graceMs) {
        this.lib = lib;
        this.graceMs = graceMs;
    }

    /**
     * Loads {@code library} (verified by the caller) and starts its writer.
     *
     * @return the running writer and, when SCHED_FIFO was refused, why (else null)
     * @throws IllegalStateException naming the library and the error when it cannot start
     */
    public static Started start(Path library, long periodMs, long graceMs, int fifoPriority) {
        if (active != null) {
            throw new IllegalStateException("a native heartbeat writer already runs in this process");
        }
        Lib lib = Native.load(library.toString(), Lib.class);
        int r = lib.arflex_beat_start(periodMs * 1_000_000L, graceMs * 1_000_000L, fifoPriority);
        if (r < 0) {
            throw new IllegalStateException("native heartbeat " + library + ": arflex_beat_start failed, errno " + -r
                    + " (period " + periodMs + " ms, grace " + graceMs + " ms, SCHED_FIFO " + fifoPriority + ")");
        }
        NativeHeartbeat b = new NativeHeartbeat(lib, graceMs);
        active = b;
        return new Started(b, r > 0 ? "errno " + r + (r == 1 ? " (EPERM)" : "") : null);
    }

    /** A started writer; {@code fifoRefused} says why it runs SCHED_OTHER, or is null. */
    public record Started(NativeHeartbeat writer, String fifoRefused) {
    }

    /** The DRCR's heartbeat round ran now. */
    public void alive() {
        lib.arflex_beat_java_alive();
    }

    public long graceMs() {
        return graceMs;
    }

    /** A snapshot of the writer's counters. */
    public Stats stats() {
        Stats s = new Stats();
        lib.arflex_beat_stats(s);
        return s;
    }

    /** Stops and joins the writer; control blocks are no longer written by it. */
    public void stop() {
        lib.arflex_beat_stop(); // first: nothing may be unmapped while a round could still write
        if (active == this) {
            active = null;
        }
    }

    static void register(Pointer ctl) {
        NativeHeartbeat b = active;
        if (b != null && ctl != null) {
            b.lib.arflex_beat_add(ctl);
        }
    }

    /** @return false when the block must stay mapped (a writer round did not end in time) */
    static boolean unregister(Pointer ctl) {
        NativeHeartbeat b = active;
        return b == null || ctl == null || b.lib.arflex_beat_remove(ctl) != -ETIMEDOUT;
    }
}
