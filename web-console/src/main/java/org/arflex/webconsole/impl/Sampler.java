package org.arflex.webconsole.impl;

import java.util.HashMap;
import java.util.LinkedHashMap;
import java.util.Map;
import java.util.function.Function;

/**
 * One sampler thread for all live streams, however many browsers watch: it reads the
 * statistics of the components somebody subscribed to at a fixed rate (10 Hz) and publishes
 * one frame; each stream waits for the next frame and writes it. The thread runs only while
 * there are subscribers, so an idle console costs the runtime nothing. Readers never call into
 * the DRCR themselves, so the load on the runtime does not grow with the number of clients.
 */
final class Sampler {
    /** Sampling period. */
    static final long PERIOD_MS = 100;

    /** One published frame: per component, a JSON-ready map. */
    record Frame(long seq, Map<String, Map<String, Object>> byComponent) {
    }

    private final Function<String, Map<String, Object>> reader;
    private final Map<String, Integer> subscribers = new HashMap<>();
    private Frame latest = new Frame(0, Map.of());
    private Thread thread;
    private boolean closed;

    /** {@code reader} returns a component's current sample, or null when it is gone. */
    Sampler(Function<String, Map<String, Object>> reader) {
        this.reader = reader;
    }

    /** Adds a subscriber of {@code name}; starts the thread if it is the first one. */
    synchronized void subscribe(String name) {
        if (closed) {
            throw new IllegalStateException("console is stopping");
        }
        subscribers.merge(name, 1, Integer::sum);
        if (thread == null) {
            thread = new Thread(this::run, "arflex-console-sampler");
            thread.setDaemon(true);
            thread.start();
        }
    }

    /** Removes a subscriber; the thread ends when none is left. */
    synchronized void unsubscribe(String name) {
        if (subscribers.merge(name, -1, Integer::sum) <= 0) {
            subscribers.remove(name);
        }
        notifyAll();
    }

    /** Waits until a frame newer than {@code seq} is out (or the timeout); null on timeout or close. */
    synchronized Frame awaitAfter(long seq, long timeoutMs) throws InterruptedException {
        long deadline = System.nanoTime() + timeoutMs * 1_000_000L;
        while (!closed && latest.seq() <= seq) {
            long left = (deadline - System.nanoTime()) / 1_000_000L;
            if (left <= 0) {
                return null;
            }
            wait(left);
        }
        return closed ? null : latest;
    }

    /** Stops the thread and wakes every stream. */
    void close() {
        Thread t;
        synchronized (this) {
            closed = true;
            t = thread;
            notifyAll();
        }
        if (t != null) {
            t.interrupt();
            try {
                t.join(2000);
            } catch (InterruptedException e) {
                Thread.currentThread().interrupt();
            }
        }
    }

    private void run() {
        long seq = 0;
        long next = System.nanoTime();
        while (true) {
            String[] names;
            synchronized (this) {
                if (closed || subscribers.isEmpty()) {
                    thread = null;
                    return;
                }
                names = subscribers.keySet().toArray(new String[0]);
            }
            Map<String, Map<String, Object>> frame = new LinkedHashMap<>();
            for (String n : names) {
                Map<String, Object> sample;
                try {
                    sample = reader.apply(n);
                } catch (RuntimeException e) {
                    sample = Map.of("error", String.valueOf(e.getMessage()));
                }
                if (sample != null) {
                    frame.put(n, sample);
                }
            }
            synchronized (this) {
                latest = new Frame(++seq, frame);
                notifyAll();
            }
            next += PERIOD_MS * 1_000_000L;
            long sleepMs = (next - System.nanoTime()) / 1_000_000L;
            if (sleepMs < 0) {
                next = System.nanoTime();
                continue;
            }
            try {
                Thread.sleep(sleepMs);
            } catch (InterruptedException e) {
                synchronized (this) {
                    thread = null;
                }
                return;
            }
        }
    }
}
