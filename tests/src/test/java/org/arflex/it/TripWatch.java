/*
 * ARFLEX integration tests.
 */
package org.arflex.it;

import java.io.IOException;
import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayDeque;
import java.util.ArrayList;
import java.util.Deque;
import java.util.List;
import java.util.Locale;

/**
 * What led to a trip of the force guard (D77): records the guard's safety output and sim-robot's
 * joint states of the last few seconds (a recorder thread, every ~200 us), so that a trip the
 * test did not cause fails it with its cause: the flags, the force, the guard's force and
 * sim-robot's release gaps over the 200 ms before it (a stall of sim-robot, D75).
 */
final class TripWatch implements AutoCloseable {
    /** Values kept of each port: 4 s at 1 kHz (the operator looks at most once a second). */
    private static final int KEEP = 4000;
    private final Deque<CellRig.Safety> safety = new ArrayDeque<>();
    private final Deque<CellRig.JointState> joints = new ArrayDeque<>();
    private final CellRig.Recorder recorder = new CellRig.Recorder();
    private final List<CellRig.Port> ports = new ArrayList<>();

    private TripWatch() {
    }

    /** Watches runtime {@code rt}'s force-guard and sim-robot, or null while either output does not exist yet. */
    static TripWatch open(Runtime rt) throws IOException {
        Path guard = rt.segment("force-guard", "safety");
        Path robot = rt.segment("sim-robot", "joint_state");
        if (!Files.exists(guard) || !Files.exists(robot)) {
            return null;
        }
        TripWatch w = new TripWatch();
        CellRig.Port g = new CellRig.Port(guard, CellRig.SAFETY_SIZE);
        w.ports.add(g);
        CellRig.Port j = new CellRig.Port(robot, CellRig.JOINT_STATE_SIZE);
        w.ports.add(j);
        w.recorder.add(g, CellRig.Safety::of, CellRig.Safety::seq, s -> w.keep(w.safety, s));
        w.recorder.add(j, CellRig.JointState::of, CellRig.JointState::seq, s -> w.keep(w.joints, s));
        w.recorder.start();
        return w;
    }

    private synchronized <V> void keep(Deque<V> d, V v) {
        d.addLast(v);
        if (d.size() > KEEP) {
            d.removeFirst();
        }
    }

    /** The first kept value of the guard with FORCE_LIMIT set (a force trip), or null. */
    synchronized CellRig.Safety trip() {
        return safety.stream().filter(s -> (s.flags() & 1) != 0).findFirst().orElse(null);
    }

    /** Forgets what was kept (after a trip that was accounted for). */
    synchronized void forget() {
        safety.clear();
        joints.clear();
    }

    /** The cause of a trip: its flags and force, the guard's force and sim-robot's release gaps over the 200 ms before it. */
    synchronized String explain(CellRig.Safety trip) {
        if (recorder.error != null) {
            return "the trip recorder failed: " + recorder.error;
        }
        if (trip == null) {
            return "no value of the guard with FORCE_LIMIT kept (the last " + safety.size() + " values)";
        }
        StringBuilder b = new StringBuilder(String.format(Locale.ROOT, "%s at %.1f N (limit %.0f N): %s%n", trip.causes(),
                trip.forceNorm(), trip.forceLimit(), trip));
        long from = trip.tNs() - 200_000_000L;
        int k = 0;
        for (CellRig.Safety s : safety) {
            if (s.tNs() > from && s.tNs() <= trip.tNs() && k++ % 10 == 0) {
                b.append(String.format(Locale.ROOT, "  guard %+.1f ms: %.1f N%n", (s.tNs() - trip.tNs()) / 1e6,
                        s.forceNorm()));
            }
        }
        CellRig.JointState prev = null;
        int gaps = 0;
        long longest = 0;
        for (CellRig.JointState j : joints) {
            if (j.tNs() > from && j.tNs() <= trip.tNs() + 20_000_000L) {
                if (prev != null && j.seq() == prev.seq() + 1 && j.tNs() - prev.tNs() > 1_500_000L) {
                    gaps++;
                    longest = Math.max(longest, j.tNs() - prev.tNs());
                    b.append(String.format(Locale.ROOT, "  sim-robot %+.1f ms: seq %d released %.1f ms after seq %d%n",
                            (j.tNs() - trip.tNs()) / 1e6, j.seq(), (j.tNs() - prev.tNs()) / 1e6, prev.seq()));
                }
                prev = j;
            }
        }
        b.append(String.format(Locale.ROOT, "  sim-robot: %d release gaps over 1.5 ms in the 200 ms before, longest %.1f ms",
                gaps, longest / 1e6));
        return b.toString();
    }

    @Override
    public void close() throws Exception {
        recorder.close();
        for (CellRig.Port p : ports) {
            p.close();
        }
    }
}
