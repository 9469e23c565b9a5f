package org.arflex.webconsole.impl;

import java.util.ArrayList;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import org.arflex.drcr.dto.UpdateProgressDTO;

/**
 * Each update of a change set as JSON, in the set's order (D60, D62): its phase, counters, its
 * shadow run's worst deviation, its verdict and why; for the live progress and the history.
 */
final class UpdateEntries {

    private UpdateEntries() {
    }

    /** The entries' fields; {@code []} for null (a DRCR that names none). */
    static List<Map<String, Object>> of(UpdateProgressDTO[] updates) {
        List<Map<String, Object>> out = new ArrayList<>();
        for (UpdateProgressDTO u : updates == null ? new UpdateProgressDTO[0] : updates) {
            Map<String, Object> e = new LinkedHashMap<>();
            e.put("component", u.component);
            e.put("phase", u.phase);
            e.put("step", u.step);
            e.put("cycle", u.cycle);
            e.put("cycles", u.cycles);
            e.put("worstField", u.worstField);
            e.put("worstDeviation", u.worstDeviation);
            e.put("tolerance", u.tolerance);
            e.put("verdict", u.verdict);
            e.put("why", u.why);
            out.add(e);
        }
        return out;
    }
}
