package org.arflex.drcr.impl.runtime;

import java.util.List;
import java.util.Locale;

/**
 * What a shadow run says (D42, D53): its progress while it runs, the summary when it passes and
 * the reasons it rejects an update for. The texts are the command's and the console's; tests
 * assert on them.
 */
final class ShadowReport {

    private ShadowReport() {
    }

    /**
     * Says how far the run is (D53): its cycles, and the compared field closest to its
     * tolerance so far (the largest difference relative to the tolerance).
     */
    static void publish(ChangeSetProgress.Apply progress, ChangeSet.Update update, String name, long pid,
                        ShadowComparison cmp, long cycles, long bad) {
        int worst = cmp.worst();
        ChangeSet.Tolerance t = worst < 0 ? null : update.tolerances().get(worst);
        double largest = worst < 0 ? 0 : cmp.largest(worst);
        progress.cycles(ChangeSetProgress.SHADOW, String.format(Locale.ROOT, "update %s: shadow run of pid %d, cycle %d "
                + "of %d, %d values compared, %d cycles late%s", name, pid, cycles,
                update.shadow(), cmp.compared(), bad, t == null ? "" : String.format(Locale.ROOT,
                        ", worst %s.%s %.3g from the running version's (tolerance %s)", t.port(), t.field(),
                        largest, t.abs())), name, cycles, update.shadow(),
                t == null ? null : t.port() + "." + t.field(), largest, t == null ? 0 : t.abs());
    }

    /** The summary of a run that passed. */
    static String passed(List<ChangeSet.Tolerance> tolerances, ShadowComparison cmp, long cycles, long newBad,
                         long oldBad) {
        StringBuilder sb = new StringBuilder(String.format(Locale.ROOT, "passed its shadow run of %d cycles "
                + "(%d cycles late, the running version %d; %d values compared", cycles, newBad,
                oldBad, cmp.compared()));
        for (int i = 0; i < tolerances.size(); i++) {
            ChangeSet.Tolerance t = tolerances.get(i);
            double largest = cmp.largest(i);
            sb.append(String.format(Locale.ROOT, ", %s.%s at most %s from the running version's (tolerance %s)",
                    t.port(), t.field(), largest == 0 ? "0" : String.format(Locale.ROOT, "%.3g", largest), t.abs()));
        }
        return sb.append(')').toString();
    }

    /**
     * The verdict's line of an update whose set was abandoned because {@code rejected}'s shadow
     * run rejected it for {@code reason} (D62).
     */
    static String cancelled(String rejected, String reason) {
        return "cancelled: update " + rejected + " was rejected in shadow (" + reason + ")";
    }

    static String overran(CycleCounts.Late late, long cycles) {
        return String.format(Locale.ROOT, "it overran or missed its deadline in %d of its %d cycles (the running "
                + "version, on the same inputs: %d; allowed %d more%s)", late.newOwn(), cycles, late.oldOwn(),
                ChangeSetExecutor.OVERRUN_ALLOWANCE, late.notCounted());
    }

    static String noneCompared(long cycles, List<ChangeSet.Tolerance> tolerances) {
        return "no value of the same source cycle of both versions could be compared in " + cycles
                + " cycles (tolerances " + tolerances + ")";
    }
}
