package org.arflex.drcr.impl.runtime;

import java.io.IOException;
import java.util.function.Consumer;
import org.arflex.drcr.impl.supervisor.RtHalf;

/**
 * The state at the switch of an update whose new half ran in shadow (docs/DECISIONS.md D61).
 * The shadow half adopted the running half's state block at its START (D41's ADOPT, sent after
 * READY) and then evolved on its own for the shadow run's cycles, its outputs not applied; a
 * cycle either half missed, or anything it reads at its own instant, puts it apart from the
 * running half by then. At the switch, before any consumer follows it, it takes the running
 * half's newest state again (READOPT, at its next cycle boundary), so the motion continues from
 * the old half's state at the switch, not from where the shadow half had got to. A re-adopt the
 * new half cannot take fails closed: the caller keeps the old half (D55's hand-back). Actor
 * thread: one mailbox round trip of a running half (its next cycle boundary), as a START is.
 */
final class ShadowSwitch {

    private ShadowSwitch() {
    }

    /**
     * Makes the shadow half {@code nextHalf} of {@code next} take {@code old}'s newest state.
     *
     * @return null when it did, or when there is no state to take (neither declares one); else
     *         why it did not, for the verdict
     */
    static String readopt(Instance old, Instance next, RtHalf nextHalf, Consumer<String> log) {
        String segment = StateTransfer.source(old, next);
        if (segment == null) {
            return null;
        }
        long t0 = System.nanoTime();
        try {
            nextHalf.readopt(segment);
        } catch (IOException | RuntimeException e) {
            return "its shadow half could not take the running half's state at the switch: " + e.getMessage();
        }
        log.accept("arflex: " + next.name + ": the shadow half (pid " + nextHalf.pid() + ") re-adopted " + segment
                + " at the switch (" + (System.nanoTime() - t0) / 1000 + " us)");
        return null;
    }
}
