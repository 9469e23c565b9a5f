package org.arflex.drcr.impl.services;

import java.util.ArrayDeque;
import java.util.ArrayList;
import java.util.Deque;
import java.util.List;
import java.util.function.LongSupplier;
import org.arflex.drcr.dto.ChangeSetDTO;
import org.arflex.drcr.dto.UpdateProgressDTO;
import org.arflex.drcr.impl.runtime.ChangeSetProgress;

/**
 * The outcomes of the change sets applied in this runtime, newest first, at most {@link #MAX}
 * (D46): what the console's Change sets page shows as its history, whether the set came from
 * the console or from {@code arflex:change apply}, each with its update entries as the live
 * progress last showed them (D62). With a {@link HistoryStore} (D66) it starts with what the
 * store kept and has the store write it after each record, so a restart of the DRCR or of the
 * runtime keeps it; without one (tests) it is in memory only.
 */
final class ChangeSetHistory {
    /** Outcomes kept; the oldest goes first. */
    static final int MAX = 50;

    private final Deque<ChangeSetDTO> entries = new ArrayDeque<>();
    private final LongSupplier clock;
    private final HistoryStore store;

    ChangeSetHistory(LongSupplier wallClockMillis) {
        this(wallClockMillis, null);
    }

    /** @param store where it is kept across restarts (its records are the start), or null: memory only */
    ChangeSetHistory(LongSupplier wallClockMillis, HistoryStore store) {
        this.clock = wallClockMillis;
        this.store = store;
        if (store != null) {
            for (ChangeSetDTO d : store.kept()) {
                if (entries.size() < MAX) {
                    entries.addLast(copy(d));
                }
            }
        }
    }

    /**
     * Records an apply's outcome (a copy, stamped with the time it came back); returns it. A
     * record without an outcome (a deployment set refused before its change set) is
     * {@code refused} (or {@code applied}), without update entries.
     */
    synchronized ChangeSetDTO record(ChangeSetDTO d) {
        d.finishedMillis = clock.getAsLong();
        if (d.outcome == null) {
            d.outcome = d.applied ? "applied" : "refused";
        }
        if (d.updates == null) {
            d.updates = new UpdateProgressDTO[0];
        }
        entries.addFirst(copy(d));
        while (entries.size() > MAX) {
            entries.removeLast();
        }
        if (store != null) {
            store.save(list()); // written off this thread; the newest list wins
        }
        return d;
    }

    /** Newest first; copies, so a caller cannot change what is kept. */
    synchronized List<ChangeSetDTO> list() {
        List<ChangeSetDTO> out = new ArrayList<>(entries.size());
        for (ChangeSetDTO d : entries) {
            out.add(copy(d));
        }
        return out;
    }

    private static ChangeSetDTO copy(ChangeSetDTO d) {
        ChangeSetDTO c = new ChangeSetDTO();
        c.actions = d.actions == null ? new String[0] : d.actions.clone();
        c.admitted = d.admitted;
        c.applied = d.applied;
        c.refusal = d.refusal;
        c.text = d.text;
        c.prepareMs = d.prepareMs;
        c.switchUs = d.switchUs;
        c.finishedMillis = d.finishedMillis;
        c.outcome = d.outcome;
        c.updates = ChangeSetProgress.copies(d.updates);
        return c;
    }
}
