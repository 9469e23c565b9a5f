package org.arflex.drcr.impl.runtime;

import java.util.concurrent.CompletableFuture;
import org.arflex.planner.Plan;

/**
 * What a change set did (D35).
 *
 * @param applied   true when switched
 * @param refusal   why not (null when applied, or when a dry run admits it)
 * @param plan      the plan of the whole set (null when refused before planning)
 * @param prepareNs from the start of preparation to the switch
 * @param switchNs  the switch's actor turn
 * @param verdict   for a set with updates (D38): completes once every update's rollback window
 *                  is over; null otherwise
 */
record SetOutcome(boolean applied, String refusal, Plan plan, long prepareNs, long switchNs,
                  CompletableFuture<String> verdict) {

    SetOutcome(boolean applied, String refusal, Plan plan, long prepareNs, long switchNs) {
        this(applied, refusal, plan, prepareNs, switchNs, null);
    }

    /** The text the shell prints: the refusal or the result, then the plan. */
    String text(ChangeSet set) {
        StringBuilder sb = new StringBuilder();
        sb.append("change set: ").append(set.describe()).append('\n');
        if (refusal != null) {
            sb.append("refused: ").append(refusal).append('\n');
        } else if (applied) {
            sb.append(String.format("applied: prepared in %.1f ms, switched in one actor turn of %.3f ms%n",
                    prepareNs / 1e6, switchNs / 1e6));
        } else {
            sb.append("admitted (dry run: nothing changed)\n");
        }
        if (plan != null) {
            sb.append(plan.toText());
        }
        return sb.toString();
    }
}
