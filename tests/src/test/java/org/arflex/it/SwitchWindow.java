package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.List;
import java.util.Locale;
import java.util.regex.Matcher;
import java.util.regex.Pattern;

/**
 * The switch turn of an applied change set, as the DRCR logs it ("switched (... monotonic A..B
 * ns)", CLOCK_MONOTONIC, the clock of every port's {@code t_ns} and of {@link System#nanoTime}),
 * and what sim-robot ran around it: the releases it did not run from {@link #BEFORE_NS} before
 * the turn to {@link #AFTER_NS} after it, when every consumer has taken its new binding (a BIND
 * is taken at the consumer's next cycle boundary, 1 ms at most after the turn that sent it).
 *
 * <p>This is the "zero missed sim-robot cycles across the switch", asserted where the
 * switch acts. Releases lost in the rest of a change set's time (preparation, shadow run,
 * window) are the machine's (D59: other tasks' kernel sections and the host's vCPU stalls on
 * this kernel) and are counted by {@code ./arflex bench reconfig} against a quiet baseline.
 */
record SwitchWindow(long fromNs, long toNs) {
    static final long BEFORE_NS = 2_000_000L;
    static final long AFTER_NS = 3_000_000L;
    private static final Pattern LINE = Pattern.compile("switched \\(.*monotonic (\\d+)\\.\\.(\\d+) ns\\)");

    /** The last switch turn in {@code log}, or an assertion error naming what was there. */
    static SwitchWindow of(List<String> log) {
        SwitchWindow w = find(log);
        assertTrue(w != null, () -> "no switch turn in the runtime's log:\n" + String.join("\n", log));
        return w;
    }

    /** The last switch turn in {@code log}, or null (a set refused, torn down or rejected in shadow). */
    static SwitchWindow find(List<String> log) {
        SwitchWindow w = null;
        for (String l : log) {
            Matcher m = LINE.matcher(l);
            if (m.find()) {
                w = new SwitchWindow(Long.parseLong(m.group(1)), Long.parseLong(m.group(2)));
            }
        }
        return w;
    }

    /**
     * {releases sim-robot did not run, states it published} from {@link #BEFORE_NS} before the turn
     * to {@link #AFTER_NS} after it, over the states {@code js} recorded (in order; a state the
     * recorder did not see is no gap: a state's release time and seq tell the releases run).
     */
    long[] skips(List<CellRig.JointState> js) {
        long from = fromNs - BEFORE_NS;
        long to = toNs + AFTER_NS;
        long missed = 0;
        long states = 0;
        for (int i = 1; i < js.size(); i++) {
            CellRig.JointState a = js.get(i - 1);
            CellRig.JointState b = js.get(i);
            if (b.tNs() < from || a.tNs() > to) {
                continue;
            }
            states += b.seq() - a.seq();
            missed += Math.round((b.tNs() - a.tNs()) / 1e6) - (b.seq() - a.seq());
        }
        return new long[] {missed, states};
    }

    /**
     * Asserts that sim-robot ran every release around the turn, and that {@code js} covers the
     * whole span (states before it and after it), so an empty recording cannot pass.
     */
    void assertNoReleaseLost(String who, List<CellRig.JointState> js) {
        long[] s = skips(js);
        long spanMs = (toNs - fromNs + BEFORE_NS + AFTER_NS) / 1_000_000L;
        System.out.printf(Locale.ROOT, "%s: the switch turn took %.3f ms; sim-robot around it (%d ms): %d releases run, "
                + "%d not run%n", who, (toNs - fromNs) / 1e6, spanMs, s[1], s[0]);
        assertTrue(!js.isEmpty() && js.get(0).tNs() < fromNs - BEFORE_NS && js.get(js.size() - 1).tNs() > toNs + AFTER_NS,
                () -> who + ": sim-robot's states recorded do not cover the switch turn " + this);
        assertTrue(s[0] == 0, () -> who + ": sim-robot did not run " + s[0] + " releases around the switch turn " + this);
    }
}
