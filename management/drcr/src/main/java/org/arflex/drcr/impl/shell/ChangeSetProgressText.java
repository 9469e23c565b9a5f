package org.arflex.drcr.impl.shell;

import java.util.Locale;
import org.arflex.drcr.dto.ChangeSetProgressDTO;

/** {@code arflex:change progress} (D53): where the set being applied is, or how the last one ended. */
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
        if (p.running) {
            sb.append("now: ").append(p.step).append('\n');
            if (p.cycles > 0) {
                sb.append(String.format(Locale.ROOT, "cycles: %d of %d (%s)%n", p.cycle, p.cycles, p.component));
            }
            if (p.worstField != null) {
                sb.append(String.format(Locale.ROOT, "worst deviation so far: %s %.3g (tolerance %s)%n", p.worstField,
                        p.worstDeviation, p.tolerance));
            }
        } else {
            sb.append("outcome: ").append(p.outcome).append(p.why == null ? "" : ": " + p.why).append('\n');
        }
        return sb.toString().stripTrailing();
    }
}
