package org.arflex.drcr.impl.runtime;

import org.arflex.drcr.impl.supervisor.RtHalf;

/**
 * Whether an update's new half can run in shadow (docs/DECISIONS.md D70). A shadow half adopts
 * the running half's state block at its START and must take it again at the switch (D61's
 * READOPT), which only a half whose configure registered a re-adopt hook can do. The half says
 * so in its control block (ControlBlock.FLAG_READOPT) before it is READY, so the change set
 * knows it before the shadow run's START, not seconds later at the switch (where D55 would hand
 * the component back). A component with no state to take (neither version declares one, or the
 * running half has none) needs no re-adopt, as {@link ShadowSwitch} skips it.
 */
final class ReadoptCheck {

    private ReadoptCheck() {
    }

    /**
     * Why the READY half {@code nextHalf} of {@code next}, the new version an update of
     * {@code set} prepared beside the running {@code old}, may not run in shadow; null when it
     * may, or when its update declares no shadow run.
     */
    static String problem(ChangeSet set, Instance old, Instance next, RtHalf nextHalf) {
        boolean shadowed = set.steps().stream().anyMatch(s -> s instanceof ChangeSet.Update u
                && u.component().equals(next.name) && u.shadow() > 0);
        if (!shadowed || StateTransfer.source(old, next) == null || nextHalf.canReadopt()) {
            return null;
        }
        return "its new RT half (pid " + nextHalf.pid() + ") registers no re-adopt hook (arflex_component_readopt), so "
                + "it cannot take the running half's state block " + next.contract.state().orElseThrow()
                + " again at the switch of a shadow run; apply it without a shadow run (shadow 0; the new half then "
                + "adopts the state at its START), or give its RT half a re-adopt hook";
    }

    /** What another update of the set says when the refusal of {@code refused} cancelled it (as D62's for a rejection). */
    static String cancelled(String refused, String reason) {
        return "cancelled: update " + refused + " was refused before its shadow run (" + reason + ")";
    }
}
