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
 * switch acts, against what the machine does anyway (D74): this VM stalls sim-robot now and then
 * with no change at all (D59: other tasks' kernel sections and the host's vCPU stalls on this
 * kernel), so a stall around the turn is the switch's only when it is longer or more frequent than
 * the same recording shows elsewhere. Releases lost over a change set's whole time (preparation,
 * shadow run, window) are counted by {@code ./arflex bench reconfig} against a quiet baseline.
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

    /** Stalls of sim-robot over some span of its states: releases not run, stalls, the longest, the span in ms. */
    record Losses(long missed, long stalls, long longest, double spanMs) {
    }

    /**
     * sim-robot's stalls over {@code js} (in order), either around the turn ({@code inside}: the
     * pairs {@link #skips} counts) or in the rest of the recording, the machine's own baseline.
     */
    Losses losses(List<CellRig.JointState> js, boolean inside) {
        long from = fromNs - BEFORE_NS;
        long to = toNs + AFTER_NS;
        long missed = 0;
        long stalls = 0;
        long longest = 0;
        double span = 0;
        for (int i = 1; i < js.size(); i++) {
            CellRig.JointState a = js.get(i - 1);
            CellRig.JointState b = js.get(i);
            boolean around = !(b.tNs() < from || a.tNs() > to);
            if (around != inside) {
                continue;
            }
            long lost = Math.round((b.tNs() - a.tNs()) / 1e6) - (b.seq() - a.seq());
            span += (b.tNs() - a.tNs()) / 1e6;
            if (lost > 0) {
                missed += lost;
                stalls++;
                longest = Math.max(longest, lost);
            }
        }
        return new Losses(missed, stalls, longest, span);
    }

    /** Below this much baseline the machine's own rate is not known: no stall around the turn is allowed. */
    static final double BASELINE_MIN_MS = 2_000;
    /** The chance that the machine alone stalls sim-robot more often around the turn than allowed. */
    static final double P_MACHINE = 1e-3;

    /**
     * The stalls the machine alone would cause in {@code windowMs} at most, but with a chance of
     * {@link #P_MACHINE}, at the rate of {@code baseline} (Poisson); 0 without enough baseline.
     */
    static long allowedStalls(Losses baseline, double windowMs) {
        if (baseline.spanMs() < BASELINE_MIN_MS || baseline.stalls() == 0) {
            return 0;
        }
        double lambda = baseline.stalls() / baseline.spanMs() * windowMs;
        double term = Math.exp(-lambda);
        double cdf = term;
        long k = 0;
        while (1 - cdf > P_MACHINE) {
            k++;
            term *= lambda / k;
            cdf += term;
        }
        return k;
    }

    /**
     * Asserts that sim-robot lost no release around the turn that the switch can be blamed for
     * (D74), and that {@code js} covers the whole span (states before it and after it), so an
     * empty recording cannot pass. This machine (not PREEMPT_RT, a VM) stalls sim-robot now and
     * then with no change at all (D59): a stall around the turn passes when the rest of the same
     * recording shows the machine stalling as often ({@link #allowedStalls}) and as long (no stall
     * around the turn longer than its longest). A switch that stalls sim-robot itself does it at
     * every switch, longer or more often, and fails; so does any loss on a machine that showed none.
     */
    void assertNoReleaseLost(String who, List<CellRig.JointState> js) {
        long spanMs = (toNs - fromNs + BEFORE_NS + AFTER_NS) / 1_000_000L;
        assertTrue(!js.isEmpty() && js.get(0).tNs() < fromNs - BEFORE_NS && js.get(js.size() - 1).tNs() > toNs + AFTER_NS,
                () -> who + ": sim-robot's states recorded do not cover the switch turn " + this);
        long[] s = skips(js);
        Losses around = losses(js, true);
        Losses machine = losses(js, false);
        long allowed = allowedStalls(machine, spanMs);
        System.out.printf(Locale.ROOT, "%s: the switch turn took %.3f ms; sim-robot around it (%d ms): %d releases run, "
                + "%d not run (%d stalls, longest %d); the rest of the recording (%.0f ms): %d not run (%d stalls, longest "
                + "%d), so the machine's own stalls around the turn: up to %d%n", who, (toNs - fromNs) / 1e6, spanMs, s[1],
                s[0], around.stalls(), around.longest(), machine.spanMs(), machine.missed(), machine.stalls(),
                machine.longest(), allowed);
        assertTrue(s[0] == 0 || (around.stalls() <= allowed && around.longest() <= machine.longest()), () -> String.format(
                Locale.ROOT, "%s: sim-robot did not run %d releases around the switch turn %s (%d stalls, longest %d "
                + "releases), more than the machine's own: in the %.0f ms of the same recording outside the turn it lost "
                + "%d releases in %d stalls (longest %d), so at most %d stalls of at most %d releases (p %.0e)", who, s[0],
                this, around.stalls(), around.longest(), machine.spanMs(), machine.missed(), machine.stalls(),
                machine.longest(), allowed, machine.longest(), P_MACHINE));
    }
}
