package org.arflex.drcr.impl.shell;

import java.util.Locale;
import org.arflex.drcr.dto.UpdateProgressDTO;

/**
 * One update's line in {@code arflex:change progress} (D60) and {@code arflex:change history}
 * (D62): its phase and cycles, its shadow run's worst deviation, its verdict.
 */
final class UpdateLine {

    private UpdateLine() {
    }

    /** {@code running}: the set is still being applied (an update without a phase is not there yet). */
    static String of(UpdateProgressDTO u, boolean running) {
        StringBuilder sb = new StringBuilder("update ").append(u.component).append(": ");
        if (u.phase == null) {
            sb.append(running ? "not in a shadow run or window yet" : "no shadow run or window");
        } else {
            sb.append(String.format(Locale.ROOT, "%s, cycle %d of %d", u.phase.equals("shadow") ? "shadow run"
                    : "rollback window", u.cycle, u.cycles));
        }
        if (u.worstField != null) {
            sb.append(String.format(Locale.ROOT, ", worst deviation in shadow %s %.3g (tolerance %s)", u.worstField,
                    u.worstDeviation, u.tolerance));
        }
        if (u.verdict != null) {
            // a cancelled update says for which update's rejection (D62); the others' why is the outcome's
            sb.append("; ").append("cancelled".equals(u.verdict) && u.why != null ? u.why : u.verdict);
        } else if (!running) {
            sb.append("; no verdict of its own");
        }
        return sb.toString();
    }
}
