package org.arflex.drcr.impl.supervisor;

import java.io.IOException;
import java.io.InputStream;
import java.net.URL;
import java.nio.file.Path;
import java.util.function.Consumer;
import org.arflex.drcr.impl.abi.NativeHeartbeat;

/**
 * Starts the runtime heartbeat's native writer for the DRCR (DECISIONS.md D17) and, each
 * heartbeat round, tells it the JVM is alive and reports the longest JVM stall it bridged. The
 * library comes out of the DRCR's own bundle through {@link VerifiedExecutables} (what is loaded
 * is what was verified). Without the library (a build with {@code -Darflex.native.skip=true}) or
 * with {@code arflex.heartbeat.native=false}, the Java round stays the only writer, as it was
 * before D17, and the log says so.
 */
public final class HeartbeatBridge {

    /** Where the library sits in the DRCR bundle. */
    public static final String ENTRY = "native/linux-x86_64/libarflex_beat.so";
    /** A bridged stall is logged when it is the longest yet and at least this long. */
    static final long REPORT_MS = 100;
    /** The writer's own lateness is logged when it is the longest yet and at least this long (D75). */
    static final long LATE_WRITER_MS = 50;

    private final NativeHeartbeat writer;
    private final Consumer<String> log;
    private long reportedNs;
    private long reportedGapNs;

    private HeartbeatBridge(NativeHeartbeat writer, Consumer<String> log) {
        this.writer = writer;
        this.log = log;
    }

    /** How the bundle's entry is found and opened (a Bundle in the runtime, a file in tests). */
    @FunctionalInterface
    public interface Entries {
        URL find(String entry);
    }

    /**
     * @param dir      a private folder for the extracted library (the DRCR's data area)
     * @param enabled  {@code arflex.heartbeat.native}
     * @return the bridge; its writer is null when the native writer does not run (logged why)
     */
    public static HeartbeatBridge open(Entries bundle, VerifiedExecutables files, Path dir, boolean enabled, long periodMs,
            long graceMs, int fifoPriority, Consumer<String> log) {
        if (!enabled) {
            log.accept("arflex: native heartbeat writer off (arflex.heartbeat.native=false): a JVM stall longer than a"
                    + " component's heartbeat timeout puts it in safe mode");
            return new HeartbeatBridge(null, log);
        }
        URL u = bundle.find(ENTRY);
        if (u == null) {
            log.accept("arflex: native heartbeat writer missing (" + ENTRY + " is not in the DRCR bundle; built with"
                    + " -Darflex.native.skip=true?): the Java heartbeat round is the only writer");
            return new HeartbeatBridge(null, log);
        }
        try {
            Path lib = files.verify(files.extract(dir, "libarflex_beat.so", () -> open(bundle)));
            NativeHeartbeat.Started s = NativeHeartbeat.start(lib, periodMs, graceMs, fifoPriority);
            log.accept("arflex: native heartbeat writer every " + periodMs + " ms, JVM stalls bridged up to " + graceMs
                    + " ms" + (s.fifoRefused() == null ? (fifoPriority > 0 ? ", SCHED_FIFO " + fifoPriority : "")
                            : ", SCHED_OTHER (SCHED_FIFO " + fifoPriority + " refused: " + s.fifoRefused() + ")"));
            return new HeartbeatBridge(s.writer(), log);
        } catch (IOException | RuntimeException | UnsatisfiedLinkError e) {
            log.accept("arflex: native heartbeat writer not started (" + e.getMessage()
                    + "): the Java heartbeat round is the only writer");
            return new HeartbeatBridge(null, log);
        }
    }

    private static InputStream open(Entries bundle) throws IOException {
        URL again = bundle.find(ENTRY);
        if (again == null) {
            throw new IOException(ENTRY + " is no longer in the DRCR bundle");
        }
        return again.openStream();
    }

    /** True when the native writer runs. */
    public boolean active() {
        return writer != null;
    }

    /** One heartbeat round of the JVM: alive now; reports a new longest bridged stall. */
    public void round() {
        if (writer == null) {
            return;
        }
        writer.alive();
        NativeHeartbeat.Stats s = writer.stats();
        long max = s.maxSilenceNs;
        if (max > reportedNs && max >= REPORT_MS * 1_000_000L) {
            reportedNs = max;
            log.accept("arflex: the JVM's heartbeat round was silent for " + max / 1_000_000L + " ms (longest yet); "
                    + (max <= writer.graceMs() * 1_000_000L ? "the native writer bridged it" : "over the grace of "
                            + writer.graceMs() + " ms: the heartbeat was withheld") + " (" + s.withheld
                    + " rounds withheld so far)");
        }
        String late = lateWriter(s.maxGapNs, reportedGapNs);
        if (late != null) {
            reportedGapNs = s.maxGapNs;
            log.accept(late);
        }
    }

    /**
     * D75: the line that says the native writer itself ran late (its thread not run: the RT halves
     * saw the heartbeat that much older whatever the JVM did), when {@code maxGapNs} is a new
     * longest at or above {@link #LATE_WRITER_MS}; else null.
     */
    static String lateWriter(long maxGapNs, long reportedGapNs) {
        if (maxGapNs <= reportedGapNs || maxGapNs < LATE_WRITER_MS * 1_000_000L) {
            return null;
        }
        return "arflex: the native heartbeat writer ran " + maxGapNs / 1_000_000L + " ms after its round before (longest"
                + " yet): its thread was not run, so every RT half saw the runtime heartbeat that much older";
    }

    /** Stops the writer. */
    public void close() {
        if (writer != null) {
            writer.stop();
        }
    }
}
