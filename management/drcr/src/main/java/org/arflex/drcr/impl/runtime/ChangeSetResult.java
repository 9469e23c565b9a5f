package org.arflex.drcr.impl.runtime;

/**
 * What planning or applying a {@link ChangeSet} gave (D35).
 *
 * @param applied   true when the set was switched
 * @param admitted  true when the whole set was admitted (a dry run that would apply it, or an applied set)
 * @param refusal   why it was refused or torn down (null otherwise)
 * @param text      the text the shell prints: the set, the outcome, the plan
 * @param prepareMs from the start of preparation to the switch
 * @param switchUs  the switch's actor turn
 * @param verdict   for a set with updates (D38): completes on the actor once every update's
 *                  rollback window is over, with one line per update (committed, or rolled back
 *                  and why); null otherwise
 */
public record ChangeSetResult(boolean applied, boolean admitted, String refusal, String text, double prepareMs,
                              double switchUs, java.util.concurrent.CompletableFuture<String> verdict) {

    public ChangeSetResult(boolean applied, boolean admitted, String refusal, String text, double prepareMs,
                           double switchUs) {
        this(applied, admitted, refusal, text, prepareMs, switchUs, null);
    }

    static ChangeSetResult of(ChangeSet set, SetOutcome o) {
        return new ChangeSetResult(o.applied(), o.refusal() == null, o.refusal(), o.text(set), o.prepareNs() / 1e6,
                o.switchNs() / 1e3, o.verdict());
    }
}
