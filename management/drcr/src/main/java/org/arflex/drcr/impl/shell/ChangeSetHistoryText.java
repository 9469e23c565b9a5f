package org.arflex.drcr.impl.shell;

import java.time.Instant;
import java.time.ZoneOffset;
import java.time.format.DateTimeFormatter;
import java.util.List;
import java.util.Locale;
import org.arflex.drcr.dto.ChangeSetDTO;
import org.arflex.drcr.dto.UpdateProgressDTO;

/**
 * {@code arflex:change history} (D62): the change sets in the history (kept across restarts, D66), newest first,
 * each with when it finished, its outcome and why, a line per update (its shadow run's or
 * window's last cycles, its worst deviation, its verdict), and the preparation and switch times
 * of a set switched in.
 */
final class ChangeSetHistoryText {

    private static final DateTimeFormatter WHEN = DateTimeFormatter.ofPattern("yyyy-MM-dd HH:mm:ss 'UTC'", Locale.ROOT)
            .withZone(ZoneOffset.UTC);

    private ChangeSetHistoryText() {
    }

    /** The newest {@code max} of {@code history} (newest first, as the service lists it). */
    static String of(List<ChangeSetDTO> history, int max) {
        if (history.isEmpty()) {
            return "no change set in the history (the newest 50 are kept in the DRCR's data area, across restarts)";
        }
        int n = Math.min(max, history.size());
        StringBuilder sb = new StringBuilder(String.format(Locale.ROOT, "%d of the %d change sets applied in this "
                + "runtime, newest first%n", n, history.size()));
        for (ChangeSetDTO d : history.subList(0, n)) {
            sb.append(WHEN.format(Instant.ofEpochMilli(d.finishedMillis))).append("  change set: ")
                    .append(String.join("; ", d.actions)).append('\n');
            sb.append("  outcome: ").append(d.outcome != null ? d.outcome : d.applied ? "applied" : "refused")
                    .append(d.refusal == null ? "" : ": " + d.refusal.strip()).append('\n');
            for (UpdateProgressDTO u : d.updates == null ? new UpdateProgressDTO[0] : d.updates) {
                sb.append("  ").append(UpdateLine.of(u, false)).append('\n');
            }
            if (d.applied) {
                sb.append(String.format(Locale.ROOT, "  prepared in %.1f ms, switch turn %.3f ms%n", d.prepareMs,
                        d.switchUs / 1e3));
            }
        }
        return sb.toString().stripTrailing();
    }
}
