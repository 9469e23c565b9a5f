package org.arflex.webconsole.impl;

import java.util.ArrayList;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import java.util.regex.Matcher;
import java.util.regex.Pattern;
import org.arflex.drcr.dto.ChangeSetDTO;

/**
 * How an applied change set ended, read from the DRCR's answer (D46), as one of
 * <ul>
 * <li>{@code committed}: switched in, and every update's rollback window (D38) ended
 * committed;</li>
 * <li>{@code rolled-back}: switched in, then an update's new version was taken back in its
 * window (D38): which component, after how many cycles, why;</li>
 * <li>{@code rejected-in-shadow}: an update's new version failed its shadow run (D42) before
 * the switch: after how many cycles, why; nothing changed;</li>
 * <li>{@code torn-down}: the preparation failed (a spawn, a READY timeout, a half that exited,
 * or the cell changed while the set was prepared); nothing changed;</li>
 * <li>{@code refused}: not admitted, or refused before anything was prepared; nothing
 * changed;</li>
 * <li>{@code applied}: switched in, but the DRCR gave no verdict of an update's window (its
 * answer says why).</li>
 * </ul>
 */
final class ChangeSetOutcome {
    private static final Pattern SHADOW = Pattern.compile(
            "^update (\\S+): rejected in shadow after (\\d+) cycles: (.*?)(?:; nothing changed.*)?$", Pattern.DOTALL);
    private static final Pattern ROLLED_BACK = Pattern.compile(
            "^update (\\S+): rolled back after (\\d+) cycles of the new version \\((.*?)\\): (.*); pid (\\d+) .*$");
    private static final Pattern COMMITTED = Pattern.compile("^update (\\S+): committed: (.*)$");
    private static final Pattern SHADOW_PASSED = Pattern.compile("^update (\\S+): passed its shadow run of (\\d+) cycles.*$");

    private ChangeSetOutcome() {
    }

    /**
     * The JSON-ready view of an apply's answer: outcome, why, per-update verdicts read from its
     * text ({@code updates}), each update's entry as the DRCR kept it ({@code entries}, D62; empty
     * from a DRCR before 0.13 of its DTOs) and the parts of its text.
     */
    static Map<String, Object> of(ChangeSetDTO d) {
        Map<String, Object> parts = ChangeSetText.parse(d.text);
        List<Map<String, Object>> updates = new ArrayList<>();
        String outcome;
        String why = null;
        Long cycles = null;
        if (!d.applied) {
            String r = d.refusal == null ? "refused without a reason" : d.refusal;
            Matcher s = SHADOW.matcher(r);
            if (s.matches()) {
                outcome = "rejected-in-shadow";
                cycles = Long.parseLong(s.group(2));
                why = s.group(3);
                updates.add(update(s.group(1), outcome, cycles, why));
            } else if (r.startsWith("preparation failed") || r.contains("the cell changed while the set was prepared")) {
                outcome = "torn-down";
                why = r;
            } else {
                outcome = "refused";
                why = r;
            }
        } else {
            boolean verdictMissing = false;
            for (Object o : (List<?>) parts.get("after")) {
                String line = (String) o;
                Matcher rb = ROLLED_BACK.matcher(line);
                Matcher c = COMMITTED.matcher(line);
                Matcher sp = SHADOW_PASSED.matcher(line);
                if (rb.matches()) {
                    updates.add(update(rb.group(1), "rolled-back", Long.parseLong(rb.group(2)), rb.group(4)));
                } else if (c.matches()) {
                    updates.add(update(c.group(1), "committed", null, c.group(2)));
                } else if (sp.matches()) {
                    Map<String, Object> u = update(sp.group(1), "passed-shadow", Long.parseLong(sp.group(2)), line);
                    updates.add(u);
                } else if (line.startsWith("warning: no verdict")) {
                    verdictMissing = true;
                    why = line;
                }
            }
            Map<String, Object> back = updates.stream().filter(u -> "rolled-back".equals(u.get("verdict")))
                    .findFirst().orElse(null);
            if (back != null) {
                outcome = "rolled-back";
                why = (String) back.get("why");
                cycles = (Long) back.get("cycles");
            } else if (verdictMissing) {
                outcome = "applied";
            } else {
                outcome = "committed";
            }
        }
        Map<String, Object> m = new LinkedHashMap<>();
        m.put("actions", d.actions == null ? List.of() : List.of(d.actions));
        m.put("outcome", outcome);
        m.put("why", why);
        m.put("cycles", cycles);
        m.put("updates", updates);
        // each update as the DRCR's live progress last showed it (D62): counters, worst deviation, verdict
        m.put("entries", UpdateEntries.of(d.updates));
        m.put("admitted", d.admitted);
        m.put("applied", d.applied);
        m.put("refusal", d.refusal);
        m.put("prepareMs", d.prepareMs);
        m.put("switchUs", d.switchUs);
        m.put("finishedMillis", d.finishedMillis);
        m.put("parts", parts);
        m.put("text", d.text);
        return m;
    }

    private static Map<String, Object> update(String component, String verdict, Long cycles, String why) {
        Map<String, Object> u = new LinkedHashMap<>();
        u.put("component", component);
        u.put("verdict", verdict);
        u.put("cycles", cycles);
        u.put("why", why);
        return u;
    }
}
