package org.arflex.drcr.impl.shell;

import java.util.Locale;
import org.arflex.drcr.dto.ChangeSetProgressDTO;
import org.arflex.drcr.dto.UpdateProgressDTO;

/**
 * {@code arflex:change progress} (D53): where the set being applied is, or how the last one ended;
 * a set of several updates gets a line for each (D60), in the set's order.
 */
final class ChangeSetProgressText {

    private ChangeSetProgressText() {
    }

    static String of(ChangeSetProgressDTO p, long nowMillis) {
        if (p == null) {
            return "no change set was applied in this runtime";
        }
        StringBuilder sb = new StringBuilder();
        sb.append("change set: ").append(String.join("; ", p.actions)).append('\n');
        if (p.running) {
            sb.append(String.format(Locale.ROOT, "applying: %s for %.1f s (began %.1f s ago; phases %s)%n", p.phase,
                    Math.max(0, nowMillis - p.phaseMillis) / 1e3, Math.max(0, nowMillis - p.startedMillis) / 1e3,
                    String.join(" > ", p.phases)));
        } else {
            sb.append(String.format(Locale.ROOT, "finished %.1f s ago, after %.1f s (phases %s)%n",
                    Math.max(0, nowMillis - p.phaseMillis) / 1e3, Math.max(0, p.phaseMillis - p.startedMillis) / 1e3,
                    String.join(" > ", p.phases)));
        }
        boolean each = p.updates != null && p.updates.length > 1;
        if (p.running) {
            sb.append("now: ").append(p.step).append('\n');
            if (each) {
                updates(sb, p);
            } else if (p.cycles > 0) {
                sb.append(String.format(Locale.ROOT, "cycles: %d of %d (%s)%n", p.cycle, p.cycles, p.component));
            }
            if (!each && p.worstField != null) {
                sb.append(String.format(Locale.ROOT, "worst deviation so far: %s %.3g (tolerance %s)%n", p.worstField,
                        p.worstDeviation, p.tolerance));
            }
        } else {
            sb.append("outcome: ").append(p.outcome).append(p.why == null ? "" : ": " + p.why).append('\n');
            if (each) {
                updates(sb, p);
            }
        }
        return sb.toString().stripTrailing();
    }

    /** One line per update (D60): its phase, cycles, its shadow run's worst deviation, its verdict. */
    private static void updates(StringBuilder sb, ChangeSetProgressDTO p) {
        for (UpdateProgressDTO u : p.updates) {
            sb.append(UpdateLine.of(u, p.running)).append('\n');
        }
    }
}
