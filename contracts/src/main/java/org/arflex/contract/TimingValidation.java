package org.arflex.contract;

import static org.arflex.contract.ContractValidator.CPUS;
import static org.arflex.contract.ContractValidator.MAX_CPU;
import static org.arflex.contract.ContractValidator.MAX_PERIOD_NS;

import java.util.ArrayList;
import java.util.List;
import java.util.TreeSet;
import org.arflex.contract.internal.ContractXml;
import org.arflex.contract.internal.Located;

/**
 * SPEC §8: checks a contract's {@code <timing>} (period, wcet, deadline, priority, CPUs, exclusive)
 * against its task type; called by {@link ContractValidator}, reports into its {@link Problems}.
 */
final class TimingValidation {
    private TimingValidation() {
    }

    static Timing check(Problems p, ContractXml x, Contract.TaskType task) {
        ContractXml.TimingXml t = x.timing;
        if (t == null) {
            if (task == Contract.TaskType.SERVICE) {
                return new Timing(0, 0, 0, 0, List.of());
            }
            p.at(x, "8", "timing", "required element <timing> is missing (needed by periodic and sporadic tasks)");
            return null;
        }
        boolean ok = true;
        boolean service = task == Contract.TaskType.SERVICE;
        Long period = duration(p, t, t.period, "timing/@period", !service);
        Long wcet = duration(p, t, t.wcet, "timing/@wcet", !service);
        Long deadline = t.deadline == null ? period : duration(p, t, t.deadline, "timing/@deadline", false);
        if ((t.period != null && period == null) || (t.wcet != null && wcet == null)
                || (t.deadline != null && deadline == null) || (!service && (period == null || wcet == null))) {
            ok = false;
        }
        if (period != null && (period <= 0 || period > MAX_PERIOD_NS)) {
            p.at(t, "8.2", "timing/@period", "period " + t.period + " is out of range (0 < period <= 60s)");
            ok = false;
        } else if (wcet != null && wcet <= 0) {
            p.at(t, "8.2", "timing/@wcet", "wcet " + t.wcet + " must be > 0");
            ok = false;
        } else if (deadline != null && deadline <= 0) {
            p.at(t, "8.2", "timing/@deadline", "deadline " + t.deadline + " must be > 0");
            ok = false;
        } else if (period != null && deadline != null && deadline > period) {
            p.at(t, "8.2", "timing/@deadline", "impossible timing: deadline " + t.deadline + " is longer than period "
                    + t.period + " (need 0 < wcet <= deadline <= period)");
            ok = false;
        } else if (wcet != null && deadline != null && wcet > deadline) {
            p.at(t, "8.2", "timing/@wcet", "impossible timing: wcet " + t.wcet + " is longer than deadline "
                    + (t.deadline == null ? t.period : t.deadline) + " (need 0 < wcet <= deadline <= period)");
            ok = false;
        } else if (service && (period == null) != (wcet == null)) {
            p.at(t, "8.5", "timing", "a service task gives both period and wcet, or neither");
            ok = false;
        }
        int priority = 0;
        if (service) {
            if (t.priority != null) {
                p.at(t, "8.5", "timing/@priority", "a service task runs at SCHED_OTHER and has no priority");
                ok = false;
            }
        } else if (t.priority == null) {
            p.at(t, "8.3", "timing/@priority", "required attribute is missing (1..98)");
            ok = false;
        } else {
            Integer pr = Values.integer(t.priority);
            if (pr == null) {
                p.at(t, "8.3", "timing/@priority", "'" + t.priority + "' is not an integer");
                ok = false;
            } else if (pr < 1 || pr > 98) {
                p.at(t, "8.3", "timing/@priority", "priority " + pr + " is out of range 1..98");
                ok = false;
            } else {
                priority = pr;
            }
        }
        List<Integer> cpus = new ArrayList<>();
        if (t.cpus != null && !t.cpus.isBlank()) {
            String c = t.cpus.replace(" ", "");
            if (!CPUS.matcher(c).matches()) {
                p.at(t, "8.4", "timing/@cpus", "'" + t.cpus + "' is not a CPU list (e.g. 1 or 0,2-3)");
                ok = false;
            } else {
                TreeSet<Integer> set = new TreeSet<>();
                for (String part : c.split(",")) {
                    String[] r = part.split("-");
                    int lo = Integer.parseInt(r[0]);
                    int hi = r.length > 1 ? Integer.parseInt(r[1]) : lo;
                    if (lo > hi || hi > MAX_CPU) {
                        p.at(t, "8.4", "timing/@cpus", "'" + part + "' is not a CPU range within 0.." + MAX_CPU);
                        ok = false;
                        break;
                    }
                    for (int i = lo; i <= hi; i++) {
                        if (!set.add(i)) {
                            p.at(t, "8.4", "timing/@cpus", "CPU " + i + " is listed twice");
                            ok = false;
                        }
                    }
                }
                cpus.addAll(set);
            }
        }
        boolean exclusive = false;
        if (t.exclusive != null) {
            Boolean b = Values.bool(t.exclusive);
            if (b == null) {
                p.at(t, "8.6", "timing/@exclusive", "'" + t.exclusive + "' is not a bool (true or false)");
                ok = false;
            } else if (service && b) {
                p.at(t, "8.6", "timing/@exclusive",
                        "a service task runs at SCHED_OTHER on no reserved CPU and cannot hold one exclusively");
                ok = false;
            } else {
                exclusive = b;
            }
        }
        if (!ok) {
            return null;
        }
        return new Timing(period == null ? 0 : period, deadline == null ? 0 : deadline, wcet == null ? 0 : wcet,
                priority, cpus, exclusive);
    }

    private static Long duration(Problems p, Located node, String text, String field, boolean required) {
        if (text == null) {
            if (required) {
                p.at(node, "8.2", field, "required attribute is missing");
            }
            return null;
        }
        Long v = Values.durationNs(text);
        if (v == null) {
            p.at(node, "8.1", field, "'" + text + "' is not a duration (integer with unit ns, us, ms or s, e.g. 50us)");
        }
        return v;
    }
}
