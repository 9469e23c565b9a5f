package org.arflex.webconsole.impl;

import java.util.HashMap;
import java.util.LinkedHashMap;
import java.util.LinkedHashSet;
import java.util.List;
import java.util.Map;
import java.util.Set;
import java.util.function.BiFunction;
import java.util.function.Function;

/**
 * One sampler thread for all live streams, however many browsers watch: it reads the
 * statistics of the components somebody subscribed to, and the values of the output ports
 * somebody watches, at a fixed rate (10 Hz), each component and each port once per period
 * whatever the number of streams that want it, and publishes one frame; each stream waits for
 * the next frame and writes its part. A subscription is a {@link Key}: a component and the
 * ports of it to watch (at most {@link #MAX_PORTS}). The thread runs only while
 * there are subscribers, so an idle console costs the runtime nothing. Readers never call into
 * the DRCR themselves, so the load on the runtime does not grow with the number of clients.
 */
final class Sampler {
    /** Sampling period. */
    static final long PERIOD_MS = 100;

    /** Most ports one stream may watch. */
    static final int MAX_PORTS = 16;

    /** What one stream watches: a component's statistics and some of its output ports. */
    record Key(String component, List<String> ports) {
        Key {
            ports = List.copyOf(new LinkedHashSet<>(ports));
        }
    }

    /**
     * One published frame: per subscription, a JSON-ready map; {@code sampled} are the
     * subscriptions it was read for (one missing from {@code byKey} is gone, one not sampled
     * subscribed after the frame was read).
     */
    record Frame(long seq, Map<Key, Map<String, Object>> byKey, Set<Key> sampled) {
    }

    private final Function<String, Map<String, Object>> reader;
    private final BiFunction<String, String, Object> portReader;
    private final Map<Key, Integer> subscribers = new HashMap<>();
    /** The newest frame; its seq keeps growing across restarts of the thread. */
    private Frame latest = new Frame(0, Map.of(), Set.of());
    private Thread thread;
    private boolean closed;

    /**
     * {@code reader} returns a component's current sample, or null when it is gone;
     * {@code portReader} the current value of one of its output ports (a JSON-ready object).
     */
    Sampler(Function<String, Map<String, Object>> reader, BiFunction<String, String, Object> portReader) {
        this.reader = reader;
        this.portReader = portReader;
    }

    /** Adds a subscriber of {@code name}; starts the thread if it is the first one. */
    synchronized void subscribe(Key name) {
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
    synchronized void unsubscribe(Key name) {
        if (subscribers.merge(name, -1, Integer::sum) <= 0) {
            subscribers.remove(name);
        }
        notifyAll();
    }

    /** Whether the sampler thread runs (for tests). */
    synchronized boolean running() {
        return thread != null;
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
        long next = System.nanoTime();
        while (true) {
            Key[] keys;
            synchronized (this) {
                if (closed || subscribers.isEmpty()) {
                    thread = null;
                    return;
                }
                keys = subscribers.keySet().toArray(new Key[0]);
            }
            // Each component and each port once, however many subscriptions share it.
            Set<String> names = new LinkedHashSet<>();
            Set<List<String>> ports = new LinkedHashSet<>();
            for (Key k : keys) {
                names.add(k.component());
                for (String p : k.ports()) {
                    ports.add(List.of(k.component(), p));
                }
            }
            Map<String, Map<String, Object>> samples = new HashMap<>();
            for (String n : names) {
                Map<String, Object> sample;
                try {
                    sample = reader.apply(n);
                } catch (RuntimeException e) {
                    sample = Map.of("error", String.valueOf(e.getMessage()));
                }
                if (sample != null) {
                    samples.put(n, sample);
                }
            }
            Map<List<String>, Object> values = new HashMap<>();
            for (List<String> cp : ports) {
                if (!samples.containsKey(cp.get(0))) {
                    continue;
                }
                Object v;
                try {
                    v = portReader.apply(cp.get(0), cp.get(1));
                } catch (RuntimeException e) {
                    v = Map.of("error", String.valueOf(e.getMessage()));
                }
                values.put(cp, v);
            }
            Map<Key, Map<String, Object>> frame = new LinkedHashMap<>();
            for (Key k : keys) {
                Map<String, Object> sample = samples.get(k.component());
                if (sample == null) {
                    continue;
                }
                if (!k.ports().isEmpty()) {
                    Map<String, Object> withPorts = new LinkedHashMap<>(sample);
                    Map<String, Object> pv = new LinkedHashMap<>();
                    for (String p : k.ports()) {
                        pv.put(p, values.get(List.of(k.component(), p)));
                    }
                    withPorts.put("ports", pv);
                    sample = withPorts;
                }
                frame.put(k, sample);
            }
            synchronized (this) {
                // Numbered after the previous frame, also one of an earlier thread: a stream that
                // saw that one waits for this one (a restart from 1 left new streams waiting).
                latest = new Frame(latest.seq() + 1, frame, Set.of(keys));
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
