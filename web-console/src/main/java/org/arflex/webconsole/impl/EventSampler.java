package org.arflex.webconsole.impl;

import java.time.Clock;
import java.time.Duration;
import java.time.Instant;
import java.util.ArrayList;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;

/**
 * Decides which of a flood of like events is written one by one: per window (one minute for
 * the console), the first {@code perKey} events of each key (an origin, a client address) and
 * at most {@code total} over all keys are <em>samples</em>; the others are only counted, and
 * once the window is over each key's count becomes one summary. At most {@code maxKeys} keys
 * are told apart per window; further ones are counted together under {@value #OTHER}. So
 * whatever arrives, a window yields at most {@code total} samples and {@code maxKeys + 1}
 * summaries. The clock is injected; nothing runs by itself: summaries of ended windows are
 * handed out by {@link #due()}, called whenever an event comes or the counts are read.
 */
final class EventSampler {
    static final String OTHER = "(other)";

    /** Events of one key in one window that were counted and not written one by one. */
    record Summary(String key, long notWritten, long seen, Instant from, Instant to) {
    }

    private static final class Count {
        long seen;
        long written;
    }

    private final Clock clock;
    private final Duration window;
    private final int perKey;
    private final int total;
    private final int maxKeys;
    private Instant start;
    private int writtenInWindow;
    private final Map<String, Count> counts = new LinkedHashMap<>();

    EventSampler(Clock clock, Duration window, int perKey, int total, int maxKeys) {
        this.clock = clock;
        this.window = window;
        this.perKey = perKey;
        this.total = total;
        this.maxKeys = maxKeys;
        this.start = clock.instant();
    }

    /** One event of {@code key}: true when it is a sample (write it), false when only counted. */
    synchronized boolean admit(String key) {
        roll();
        String k = key == null ? "(none)" : key;
        if (!counts.containsKey(k) && counts.size() >= maxKeys) {
            k = OTHER;
        }
        Count c = counts.computeIfAbsent(k, x -> new Count());
        c.seen++;
        if (c.written < perKey && writtenInWindow < total) {
            c.written++;
            writtenInWindow++;
            return true;
        }
        return false;
    }

    /** The summaries of windows that have ended and had events not written; each handed out once. */
    synchronized List<Summary> due() {
        return roll();
    }

    /** Every count not written yet, the current window's included (at shutdown); each handed out once. */
    synchronized List<Summary> drain() {
        List<Summary> out = roll();
        out.addAll(summaries(clock.instant()));
        counts.clear();
        writtenInWindow = 0;
        return out;
    }

    /** Per key, the events of the current window not written one by one (so far). */
    synchronized Map<String, Long> pending() {
        roll();
        Map<String, Long> m = new LinkedHashMap<>();
        counts.forEach((k, c) -> {
            if (c.seen > c.written) {
                m.put(k, c.seen - c.written);
            }
        });
        return m;
    }

    private List<Summary> roll() {
        Instant now = clock.instant();
        List<Summary> out = new ArrayList<>();
        if (now.isBefore(start.plus(window))) {
            return out;
        }
        out.addAll(summaries(start.plus(window)));
        counts.clear();
        writtenInWindow = 0;
        // the window now is the one that holds now, aligned on the first one
        long n = Duration.between(start, now).toNanos() / window.toNanos();
        start = start.plus(window.multipliedBy(n));
        return out;
    }

    private List<Summary> summaries(Instant to) {
        List<Summary> out = new ArrayList<>();
        counts.forEach((k, c) -> {
            if (c.seen > c.written) {
                out.add(new Summary(k, c.seen - c.written, c.seen, start, to));
            }
        });
        return out;
    }
}
