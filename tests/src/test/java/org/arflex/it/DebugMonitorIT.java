package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.io.IOException;
import java.nio.ByteOrder;
import java.nio.MappedByteBuffer;
import java.nio.channels.FileChannel;
import java.nio.file.Files;
import java.nio.file.Path;
import java.nio.file.StandardOpenOption;
import java.util.ArrayList;
import java.util.List;
import java.util.Map;
import java.util.concurrent.ConcurrentHashMap;
import java.util.concurrent.atomic.AtomicLong;
import java.util.concurrent.atomic.AtomicReference;
import java.util.regex.Matcher;
import java.util.regex.Pattern;
import org.junit.jupiter.api.Test;

/**
 * Structure adaptation as in the paper: while the sample pair runs, an engineer installs the
 * debug monitor (bundles/debug-monitor), watches internal values of the running components
 * through it (sample-counter.count and sample-scaler.y, read-only), changes a parameter and
 * sees the monitor observe it, and uninstalls the monitor again. Throughout, sample-counter
 * and sample-scaler keep their processes and keep cycling. The monitor's outputs are read
 * straight from shared memory; the runtime's leak check ({@link Runtime#close()}) runs at the
 * end.
 */
class DebugMonitorIT {

    static final Path COUNTER = CellIT.COUNTER;
    static final Path SCALER = CellIT.SCALER;
    /** The debug-monitor bundle as built in this tree. */
    static final Path DEBUGMON = Components.jar("debug-monitor");
    static final long T = 30_000;
    static final String[] PAIR = {"sample-counter", "sample-scaler"};

    /** A state port of arflex.Sample mapped once (ABI.md §4: slot 0 and its value at Ports.SLOT0_SEQ/SLOT0_VALUE). */
    static final class StatePort implements AutoCloseable {
        private final FileChannel ch;
        private final MappedByteBuffer b;

        StatePort(Path segment) throws IOException {
            ch = FileChannel.open(segment, StandardOpenOption.READ);
            b = ch.map(FileChannel.MapMode.READ_ONLY, 0, 4096);
            b.order(ByteOrder.LITTLE_ENDIAN);
        }

        /** The current value, or null (never written, or torn on every attempt). */
        Ports.Sample read() {
            for (int attempt = 0; attempt < 100; attempt++) {
                long s1 = b.getLong(Ports.SLOT0_SEQ);
                if (s1 == 0) {
                    return null;
                }
                if ((s1 & 1) != 0) {
                    continue;
                }
                Ports.Sample v = new Ports.Sample(b.getLong(Ports.SLOT0_VALUE), b.getLong(Ports.SLOT0_VALUE + 8),
                        b.getDouble(Ports.SLOT0_VALUE + 16));
                if (b.getLong(Ports.SLOT0_SEQ) == s1) {
                    return v;
                }
            }
            return null;
        }

        @Override
        public void close() throws IOException {
            ch.close();
        }
    }

    /**
     * Records every value of the pair's ports it sees (seq -> value), polling every 2 ms in a
     * thread of its own, and checks that the counter's sequence never goes backwards (a
     * restarted counter would start again at 1).
     */
    static final class PairRecorder implements AutoCloseable {
        final Map<Long, Double> xs = new ConcurrentHashMap<>();
        final Map<Long, Double> ys = new ConcurrentHashMap<>();
        final AtomicReference<String> error = new AtomicReference<>();
        final AtomicLong maxSeqStep = new AtomicLong();
        private final StatePort x;
        private final StatePort y;
        private final Thread thread;
        private volatile boolean stop;

        PairRecorder(Runtime rt) throws IOException {
            x = new StatePort(rt.segment("sample-counter", "count"));
            y = new StatePort(rt.segment("sample-scaler", "y"));
            thread = new Thread(this::run, "debugmon-recorder");
            thread.setDaemon(true);
            thread.start();
        }

        private void run() {
            long last = 0;
            while (!stop) {
                Ports.Sample a = x.read();
                Ports.Sample b = y.read();
                if (a != null) {
                    if (a.seq() < last && error.get() == null) {
                        error.set("sample-counter's seq went back from " + last + " to " + a.seq());
                    }
                    if (last != 0 && a.seq() > last) {
                        maxSeqStep.accumulateAndGet(a.seq() - last, Math::max);
                    }
                    last = Math.max(last, a.seq());
                    xs.put(a.seq(), a.value());
                }
                if (b != null) {
                    ys.put(b.seq(), b.value());
                }
                try {
                    Thread.sleep(2); // sampling interval of a recorder, not a wait for a condition
                } catch (InterruptedException e) {
                    return;
                }
            }
        }

        @Override
        public void close() throws Exception {
            stop = true;
            thread.interrupt();
            thread.join(10_000);
            x.close();
            y.close();
        }
    }

    /** Pids and cycle counters of the pair, checked at every step of the sequence. */
    static final class PairWatch {
        final Runtime rt;
        final long[] pids = new long[PAIR.length];
        final long[] cycles = new long[PAIR.length];
        final List<String> rows = new ArrayList<>();

        PairWatch(Runtime rt) {
            this.rt = rt;
            for (int i = 0; i < PAIR.length; i++) {
                pids[i] = rt.pid(PAIR[i]);
                assertTrue(pids[i] > 0, PAIR[i] + " has no process");
            }
        }

        /** Same pids, ACTIVE, and cycle counters past the previous checkpoint's. */
        void checkpoint(String step) {
            for (int i = 0; i < PAIR.length; i++) {
                String name = PAIR[i];
                long before = cycles[i];
                long[] now = new long[2];
                rt.waitUntil(name + " cycles past " + before + " at step '" + step + "'", T, () -> {
                    Map<String, Object> inst = rt.instance(name);
                    assertEquals("ACTIVE", inst.get("state"), name + " at step '" + step + "'");
                    assertEquals(pids[PAIR_INDEX.get(name)], ((Number) inst.get("pid")).longValue(),
                            name + " was restarted at step '" + step + "'");
                    @SuppressWarnings("unchecked")
                    Map<String, Object> st = (Map<String, Object>) inst.get("stats");
                    if (st == null) {
                        return false;
                    }
                    now[0] = ((Number) st.get("cycles")).longValue();
                    now[1] = ((Number) st.get("overruns")).longValue();
                    return now[0] > before;
                });
                cycles[i] = now[0];
                rows.add(String.format("%-34s %-15s cycles %8d  overruns %4d", step, name, now[0], now[1]));
            }
        }

        void report() {
            System.out.println("DebugMonitorIT: the pair across the sequence (pids " + pids[0] + ", " + pids[1]
                    + " unchanged; overruns reported, not asserted)");
            rows.forEach(r -> System.out.println("  " + r));
        }
    }

    static final Map<String, Integer> PAIR_INDEX = Map.of(PAIR[0], 0, PAIR[1], 1);

    /**
     * Waits until the monitor has shown {@code n} samples on m0_last and m1_last that match
     * what the pair itself published: m0_last is a verbatim copy of a counter value, m1_last of
     * a scaler value, and that scaler value is {@code gain} times the counter value of the same
     * seq.
     */
    static void assertMonitorFollows(Runtime rt, PairRecorder rec, StatePort m0, StatePort m1, double gain, int n) {
        int[] matched = {0, 0};
        long[] lastSeen = {-1, -1};
        rt.waitUntil("the monitor to show " + n + " values of each port with y = " + gain + " * x", T, () -> {
            assertEquals(null, rec.error.get());
            Ports.Sample a = m0.read();
            if (a != null && a.seq() != lastSeen[0] && rec.xs.containsKey(a.seq())) {
                assertEquals(rec.xs.get(a.seq()), a.value(), 0.0, "m0_last of seq " + a.seq() + " vs sample-counter.count");
                lastSeen[0] = a.seq();
                matched[0]++;
            }
            Ports.Sample b = m1.read();
            if (b != null && b.seq() != lastSeen[1] && rec.ys.containsKey(b.seq()) && rec.xs.containsKey(b.seq())) {
                assertEquals(rec.ys.get(b.seq()), b.value(), 0.0, "m1_last of seq " + b.seq() + " vs sample-scaler.y");
                lastSeen[1] = b.seq();
                // a value written before the new gain reached the scaler does not count
                if (Math.abs(gain * rec.xs.get(b.seq()) - b.value()) <= 1e-9) {
                    matched[1]++;
                }
            }
            return matched[0] >= n && matched[1] >= n;
        });
    }

    @Test
    void debugMonitorInstalledWatchedAndRemovedWhileThePairKeepsCycling() throws Exception {
        assertTrue(Files.isRegularFile(DEBUGMON), "debug-monitor bundle not built: " + DEBUGMON);
        try (Runtime rt = new Runtime("debug-monitor")) {
            rt.installAndStart(COUNTER);
            rt.installAndStart(SCALER);
            rt.awaitState("ACTIVE", T, PAIR);
            CellIT.assertDataFlows(rt, 2.0);
            PairWatch watch = new PairWatch(rt);
            watch.checkpoint("pair running");
            try (PairRecorder rec = new PairRecorder(rt)) {
                // install the monitor at run time, as an engineer would from the shell
                long mon = rt.installAndStart(DEBUGMON);
                rt.awaitState("ACTIVE", T, "debug-monitor");
                watch.checkpoint("monitor installed");
                String bindings = rt.cmd("arflex:bindings");
                assertTrue(bindings.contains("debug-monitor.m0 <- sample-counter.count"), bindings);
                assertTrue(bindings.contains("debug-monitor.m1 <- sample-scaler.y"), bindings);
                assertTrue(bindings.contains("sample-scaler.x <- sample-counter.count"), bindings);
                try (StatePort m0 = new StatePort(rt.segment("debug-monitor", "m0_last"));
                        StatePort m1 = new StatePort(rt.segment("debug-monitor", "m1_last"))) {
                    assertMonitorFollows(rt, rec, m0, m1, 2.0, 5);
                    watch.checkpoint("monitor following (gain 2)");
                    assertConsoleReadsTheCounter(rt);

                    // the engineer retunes the scaler and sees the monitor observe the new scaling
                    assertEquals("sample-scaler.gain = 3.5", rt.cmd("arflex:set sample-scaler gain 3.5"));
                    assertMonitorFollows(rt, rec, m0, m1, 3.5, 5);
                    watch.checkpoint("gain 3.5 observed");

                    // statistics over short windows: min <= mean <= max, within the sine's range
                    assertEquals("debug-monitor.window = 5", rt.cmd("arflex:set debug-monitor window 5"));
                    checkWindows(rt, 1.0, 3.5);
                    watch.checkpoint("windows of 5 observed");
                }

                // remove it again
                assertEquals("", rt.cmd("uninstall " + mon));
                rt.waitUntil("debug-monitor gone (instance, process, ports)", T, () -> {
                    Map<String, Object> i = rt.instance("debug-monitor");
                    boolean gone = i == null || "DESTROYED".equals(i.get("state"));
                    return gone && !Files.exists(rt.segment("debug-monitor", "m0_last"))
                            && Runtime.rtProcesses(rt.rid).stream().noneMatch(p -> p.contains("--instance debug-monitor"));
                });
                assertEquals("sample-scaler.x <- sample-counter.count", rt.cmd("arflex:bindings"));
                watch.checkpoint("monitor uninstalled");
                CellIT.assertDataFlows(rt, 3.5);
                watch.checkpoint("end");
                assertEquals(null, rec.error.get());
                System.out.println("DebugMonitorIT: counter values recorded " + rec.xs.size()
                        + ", largest seq step between two recorder polls " + rec.maxSeqStep.get());
            }
            watch.report();
        }
    }

    /**
     * The runtime's own port reader (arflex:port, the DRCR's PortReader in the runtime JVM) reads the
     * counter's state port as a C producer writes it (port ABI 2.0, DECISIONS.md D30): the seq it shows
     * lies between two direct reads of the segment around the command, so the JVM, this test's
     * reader and the RT half agree on the slot layout.
     */
    static void assertConsoleReadsTheCounter(Runtime rt) throws IOException {
        Path seg = rt.segment("sample-counter", "count");
        Ports.Sample before = Ports.readState(seg);
        String pv = rt.cmd("arflex:port sample-counter count");
        Ports.Sample after = Ports.readState(seg);
        Matcher m = Pattern.compile("(?m)^  seq = (\\d+)\\b").matcher(pv);
        assertTrue(before != null && after != null && pv.startsWith("sample-counter.count (arflex.Sample")
                && pv.contains(": element ") && m.find(), pv);
        long seq = Long.parseLong(m.group(1));
        assertTrue(before.seq() <= seq && seq <= after.seq(),
                "console seq " + seq + " not within direct reads " + before.seq() + ".." + after.seq() + ": " + pv);
    }

    /** Waits for 3 new windows on m0 and m1; checks each window's min <= mean <= max and range. */
    static void checkWindows(Runtime rt, double amplitude, double gain) throws IOException {
        String[] slots = {"m0", "m1"};
        double[] bound = {amplitude, Math.abs(gain) * amplitude};
        for (int k = 0; k < slots.length; k++) {
            String s = slots[k];
            double range = bound[k];
            double lim = range + 1e-9;
            try (StatePort mn = new StatePort(rt.segment("debug-monitor", s + "_min"));
                    StatePort mx = new StatePort(rt.segment("debug-monitor", s + "_max"));
                    StatePort mean = new StatePort(rt.segment("debug-monitor", s + "_mean"))) {
                long[] first = {-1};
                int[] seen = {0};
                long[] lastWin = {-1};
                rt.waitUntil("3 new windows of " + s, T, () -> {
                    Ports.Sample a = mn.read();
                    Ports.Sample b = mx.read();
                    Ports.Sample c = mean.read();
                    if (a == null || b == null || c == null || a.seq() != b.seq() || b.seq() != c.seq()) {
                        return false; // none yet, or caught between the three writes of one window
                    }
                    if (first[0] < 0) {
                        first[0] = a.seq(); // may be a window of the old size
                        return false;
                    }
                    if (a.seq() != lastWin[0]) {
                        lastWin[0] = a.seq();
                        assertTrue(a.value() <= c.value() && c.value() <= b.value(),
                                s + " window " + a.seq() + ": min " + a.value() + " mean " + c.value() + " max " + b.value());
                        assertTrue(Math.abs(a.value()) <= lim && Math.abs(b.value()) <= lim,
                                s + " window " + a.seq() + " beyond +-" + range + ": " + a.value() + ".." + b.value());
                        seen[0]++;
                    }
                    return seen[0] >= 3;
                });
            }
        }
    }
}
