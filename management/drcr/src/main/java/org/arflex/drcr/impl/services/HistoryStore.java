package org.arflex.drcr.impl.services;

import java.io.IOException;
import java.nio.file.Path;
import java.util.List;
import java.util.concurrent.ExecutorService;
import java.util.concurrent.Executors;
import java.util.concurrent.TimeUnit;
import java.util.concurrent.atomic.AtomicReference;
import java.util.function.Consumer;
import org.arflex.drcr.dto.ChangeSetDTO;

/**
 * Keeps the change-set history across restarts of the DRCR (D66): what {@link HistoryFile} read
 * at the start, and a thread of its own that writes the newest history after each record, so no
 * caller (nor the actor) waits on the disk. Records that come faster than the disk are written
 * together: the writer takes the newest list. {@link #close} writes what is pending, with a
 * deadline.
 */
public final class HistoryStore {

    private final HistoryFile file;
    private final Consumer<String> log;
    private final List<ChangeSetDTO> kept;
    private final AtomicReference<List<ChangeSetDTO>> pending = new AtomicReference<>();
    private final ExecutorService writer = Executors.newSingleThreadExecutor(r -> {
        Thread t = new Thread(r, "arflex-drcr-history");
        t.setDaemon(true);
        return t;
    });

    private HistoryStore(HistoryFile file, Consumer<String> log) {
        this.file = file;
        this.log = log;
        this.kept = file.load();
    }

    /**
     * Reads the history kept in {@code folder} (the DRCR's data area).
     *
     * @param uid the runtime's effective uid, the only owner the file may have
     */
    public static HistoryStore open(Path folder, long uid, Consumer<String> log) {
        return new HistoryStore(new HistoryFile(folder, uid, log), log);
    }

    /** Where the history is kept. */
    public Path path() {
        return file.path();
    }

    /** What was read at the start, newest first. */
    List<ChangeSetDTO> kept() {
        return kept;
    }

    /** Has {@code records} (a copy no one changes) written soon, off the caller's thread. */
    void save(List<ChangeSetDTO> records) {
        if (pending.getAndSet(records) == null) {
            try {
                writer.execute(this::writePending);
            } catch (java.util.concurrent.RejectedExecutionException e) {
                log.accept("arflex: change-set history: not written after the DRCR stopped (" + records.size() + " sets)");
            }
        }
    }

    private void writePending() {
        List<ChangeSetDTO> l = pending.getAndSet(null);
        if (l == null) {
            return;
        }
        try {
            file.write(l);
        } catch (IOException | RuntimeException e) {
            log.accept("arflex: change-set history: " + file.path() + " not written: " + e);
        }
    }

    /** Writes what is pending, waiting at most {@code ms}; then takes no more. */
    public void close(long ms) {
        writer.shutdown();
        try {
            if (!writer.awaitTermination(ms, TimeUnit.MILLISECONDS)) {
                log.accept("arflex: change-set history: the last write to " + file.path() + " did not end within " + ms
                        + " ms");
            }
        } catch (InterruptedException e) {
            Thread.currentThread().interrupt();
        }
    }
}
