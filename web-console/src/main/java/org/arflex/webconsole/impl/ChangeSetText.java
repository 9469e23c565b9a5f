package org.arflex.webconsole.impl;

import java.util.ArrayList;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import java.util.regex.Matcher;
import java.util.regex.Pattern;

/**
 * The DRCR's text of a change set ({@code ChangeSetDTO.text}, what {@code arflex:change} prints)
 * read into the parts the Change sets page shows (D46): the outcome line, then the planner's
 * plan of the whole set (steps START/STOP/RESTART/REBIND/HOLD with their reasons, stop and
 * start order, wiring, the admission per CPU, memory and network, what is not active after and
 * why, notes; per CPU its load while both halves of an update run, in the shadow run and the
 * rollback window, and why such a phase is not schedulable: D51), and the lines the apply added after the plan (bundles started or stopped, shadow
 * runs, the verdicts of update windows, warnings). A line it does not know is kept in
 * {@code after}, and the page shows the text as the DRCR wrote it beside the parts, so nothing
 * the DRCR says is lost to this reading.
 */
final class ChangeSetText {
    private static final Pattern STEP = Pattern.compile("^  (START|STOP|RESTART|REBIND|HOLD)\\s+(\\S+)\\s+(.*)$");
    private static final Pattern CPU = Pattern.compile("^  cpu (\\S+)\\s+U=([0-9.]+)/([0-9.]+)\\s+(.*?)(?:  (.*))?$");
    /** A CPU's load while both halves of an update run, under its own line (D51). */
    private static final Pattern TRANSIENT = Pattern.compile(
            "^    (shadow|window) \\((\\d+) cycles?\\)\\s+U=([0-9.]+)/([0-9.]+)\\s+(.*?)(?:  (.*))?$");
    private static final Pattern NOT_ACTIVE = Pattern.compile("^  (\\S+)\\s+(.*)$");

    private ChangeSetText() {
    }

    /** The parts of {@code text}; never null, empty parts when the text has none. */
    static Map<String, Object> parse(String text) {
        String describe = null;
        String outcome = null;
        String title = null;
        List<Map<String, String>> steps = new ArrayList<>();
        List<String> wiring = new ArrayList<>();
        List<String> cycles = new ArrayList<>();
        List<Map<String, Object>> cpus = new ArrayList<>();
        List<Map<String, String>> notActive = new ArrayList<>();
        List<String> notes = new ArrayList<>();
        List<String> transientRefusals = new ArrayList<>();
        List<String> after = new ArrayList<>();
        String stopOrder = null;
        String startOrder = null;
        String memory = null;
        String section = null;
        boolean inPlan = false;
        StringBuilder plan = new StringBuilder();
        for (String line : (text == null ? "" : text).split("\n")) {
            if (line.isEmpty()) {
                continue;
            }
            if (inPlan && line.startsWith("  ") && section != null) {
                plan.append(line).append('\n');
                switch (section) {
                    case "actions" -> {
                        Matcher m = STEP.matcher(line);
                        if (m.matches()) {
                            steps.add(Map.of("op", m.group(1), "component", m.group(2), "reason", m.group(3).strip()));
                        } else {
                            after.add(line.strip());
                        }
                    }
                    case "wiring" -> wiring.add(line.strip());
                    case "cycles" -> cycles.add(line.strip());
                    case "cpus" -> {
                        Matcher m = CPU.matcher(line);
                        if (m.matches()) {
                            Map<String, Object> c = new LinkedHashMap<>();
                            c.put("cpu", m.group(1));
                            c.put("utilisation", Double.parseDouble(m.group(2)));
                            c.put("cap", Double.parseDouble(m.group(3)));
                            c.put("test", m.group(4).strip());
                            c.put("tasks", m.group(5) == null ? List.of() : List.of(m.group(5).strip().split(", ")));
                            c.put("transient", new ArrayList<Map<String, Object>>());
                            cpus.add(c);
                        } else if ((m = TRANSIENT.matcher(line)).matches() && !cpus.isEmpty()) {
                            Map<String, Object> t = new LinkedHashMap<>();
                            t.put("phase", m.group(1));
                            t.put("cycles", Long.parseLong(m.group(2)));
                            t.put("utilisation", Double.parseDouble(m.group(3)));
                            t.put("cap", Double.parseDouble(m.group(4)));
                            t.put("test", m.group(5).strip());
                            t.put("tasks", m.group(6) == null ? List.of() : List.of(m.group(6).strip().split(", ")));
                            @SuppressWarnings("unchecked")
                            List<Map<String, Object>> l = (List<Map<String, Object>>) cpus.get(cpus.size() - 1)
                                    .get("transient");
                            l.add(t);
                        } else {
                            after.add(line.strip());
                        }
                    }
                    case "not active" -> {
                        Matcher m = NOT_ACTIVE.matcher(line);
                        if (m.matches()) {
                            notActive.add(Map.of("component", m.group(1), "reason", m.group(2).strip()));
                        }
                    }
                    case "notes" -> notes.add(line.strip());
                    case "not schedulable while both halves run" -> transientRefusals.add(line.strip());
                    default -> after.add(line.strip());
                }
                continue;
            }
            section = null;
            if (describe == null && line.startsWith("change set: ")) {
                describe = line.substring("change set: ".length());
            } else if (outcome == null && !inPlan && (line.startsWith("refused: ") || line.startsWith("applied: ")
                    || line.startsWith("admitted"))) {
                outcome = line;
            } else if (title == null && line.startsWith("plan: ")) {
                title = line.substring("plan: ".length());
                inPlan = true;
                plan.append(line).append('\n');
            } else if (inPlan && line.startsWith("actions:")) {
                section = "actions";
                plan.append(line).append('\n');
            } else if (inPlan && line.startsWith("stop order: ")) {
                stopOrder = line.substring("stop order: ".length());
                plan.append(line).append('\n');
            } else if (inPlan && line.startsWith("start order: ")) {
                startOrder = line.substring("start order: ".length());
                plan.append(line).append('\n');
            } else if (inPlan && (line.startsWith("wiring:") || line.startsWith("cycles:") || line.startsWith("cpus:")
                    || line.startsWith("not active:") || line.startsWith("notes:")
                    || line.startsWith("not schedulable while both halves run:"))) {
                section = line.substring(0, line.indexOf(':'));
                plan.append(line).append('\n');
            } else if (inPlan && line.startsWith("memory: ")) {
                memory = line.substring("memory: ".length());
                plan.append(line).append('\n');
            } else {
                // after the plan: what the apply added (bundles, shadow runs, verdicts, warnings)
                inPlan = inPlan && line.startsWith("  ");
                after.add(line.strip());
            }
        }
        Map<String, Object> m = new LinkedHashMap<>();
        m.put("describe", describe);
        m.put("outcomeLine", outcome);
        m.put("title", title);
        m.put("steps", steps);
        m.put("stopOrder", stopOrder);
        m.put("startOrder", startOrder);
        m.put("wiring", wiring);
        m.put("cycles", cycles);
        m.put("cpus", cpus);
        m.put("memory", memory);
        m.put("notActive", notActive);
        m.put("notes", notes);
        m.put("transientRefusals", transientRefusals);
        m.put("after", after);
        m.put("planText", plan.toString());
        return m;
    }

    /** The planner's part of {@code text} only (from {@code plan:} to the end of its sections). */
    static String planPart(String text) {
        return (String) parse(text).get("planText");
    }
}
