package org.arflex.planner.impl;

import java.util.ArrayList;
import java.util.Comparator;
import java.util.List;
import java.util.Map;
import java.util.Set;
import java.util.TreeMap;
import java.util.TreeSet;
import java.util.function.Function;
import org.arflex.contract.Contract;
import org.arflex.planner.AdmissionResult;
import org.arflex.planner.Capacities;
import org.arflex.planner.Change;
import org.arflex.planner.CpuAdmissionTest;
import org.arflex.planner.CpuAdmissionTest.Task;
import org.arflex.planner.CpuLoad;
import org.arflex.planner.Decision;
import org.arflex.planner.TransientLoad;
import org.arflex.planner.TransientLoad.Phase;

/**
 * The CPU load while both halves of an update run (docs/DECISIONS.md D51), as the DRCR runs them:
 *
 * <ul>
 * <li><b>shadow</b>: nothing of the set is switched yet, so the Active components run on their
 * current CPUs with their current contracts, and each update with a shadow run adds its new half
 * on the CPU the plan gives the new version (the DRCR spawns it with that CPU's mask);</li>
 * <li><b>window</b>: the plan's configuration runs (the set's installs started, its uninstalls
 * stopped, each updated component's new half on its planned CPU), and each update with a window
 * adds its old half, which keeps the CPU and the contract it was started with.</li>
 * </ul>
 *
 * <p>A second half counts with its WCET (the larger of the declared and the measured one, as
 * admission takes it) at its own priority; its outputs being read by nobody changes nothing of
 * its cost. Each CPU where a second half runs is judged from scratch by the plan's
 * {@link CpuAdmissionTest}: the tasks already there, most urgent first, then the second halves
 * (the cap first, then the test), so only those CPUs cost anything, and a change without
 * {@link Change#overlaps() overlaps} costs nothing.
 */
final class Transients {

    private Transients() {
    }

    /**
     * Refuses an overlap of a component that {@code change} does not replace: an overlap is the
     * old and the new half of an update, so its component is one the change puts
     * ({@code put}) and that was installed before it (not in {@code installed}, the change's
     * new components).
     *
     * @throws IllegalArgumentException naming the first such overlap
     */
    static void checkOverlaps(Change change, Set<String> put, Set<String> installed) {
        for (Change.Overlap o : change.overlaps().values()) {
            if (!put.contains(o.component()) || installed.contains(o.component())) {
                throw new IllegalArgumentException("overlap '" + o.component() + "': the change does not replace it "
                        + "(an overlap is the old and the new half of an update)");
            }
        }
    }

    /** How the tasks of one phase are placed: the base configuration plus the second halves. */
    private record Extra(String component, int cpu, Task task, long cycles) {
    }

    /**
     * The transient loads of {@code change}'s overlaps.
     *
     * @param change         the change, with its overlaps
     * @param cpuBefore      CPU of each Active periodic or sporadic component before the change
     * @param before         the contract of a component before the change
     * @param measuredBefore measured WCETs before the change
     * @param capsBefore     capacities before the change
     * @param after          the plan's admission
     * @param afterContract  the contract of a component after the change
     * @param test           the plan's CPU test
     * @return the SHADOW phase then the WINDOW phase, each only when some second half runs in it
     */
    static List<TransientLoad> of(Change change, Map<String, Integer> cpuBefore, Function<String, Contract> before,
            Map<String, Long> measuredBefore, Capacities capsBefore, AdmissionResult after,
            Function<String, Contract> afterContract, CpuAdmissionTest test) {
        List<Extra> shadow = new ArrayList<>();
        List<Extra> window = new ArrayList<>();
        long shadowCycles = 0;
        long windowCycles = 0;
        for (Change.Overlap o : change.overlaps().values()) {
            String n = o.component();
            Integer oldCpu = cpuBefore.get(n);
            Decision d = after.decisions().get(n);
            boolean newRuns = d != null && d.admitted() && d.cpu().isPresent();
            if (o.shadowCycles() > 0 && newRuns && oldCpu != null) {
                Contract c = afterContract.apply(n);
                shadow.add(new Extra(n, d.cpu().getAsInt(), task(n + " (new)", c, d.wcetNs()), o.shadowCycles()));
                shadowCycles = Math.max(shadowCycles, o.shadowCycles());
            }
            if (o.windowCycles() > 0 && newRuns && oldCpu != null) {
                Contract c = before.apply(n);
                long wcet = Math.max(c.timing().wcetNs(), measuredBefore.getOrDefault(n, 0L));
                window.add(new Extra(n, oldCpu, task(n + " (old)", c, wcet), o.windowCycles()));
                windowCycles = Math.max(windowCycles, o.windowCycles());
            }
        }
        List<TransientLoad> out = new ArrayList<>(2);
        if (!shadow.isEmpty()) {
            Set<Integer> touched = cpus(shadow);
            Map<Integer, List<Task>> base = new TreeMap<>();
            for (var e : cpuBefore.entrySet()) {
                if (touched.contains(e.getValue())) {
                    Contract c = before.apply(e.getKey());
                    long wcet = Math.max(c.timing().wcetNs(), measuredBefore.getOrDefault(e.getKey(), 0L));
                    base.computeIfAbsent(e.getValue(), k -> new ArrayList<>()).add(task(e.getKey(), c, wcet));
                }
            }
            out.add(phase(Phase.SHADOW, shadowCycles, shadow, base, capsBefore, test));
        }
        if (!window.isEmpty()) {
            Set<Integer> touched = cpus(window);
            Map<Integer, List<Task>> base = new TreeMap<>();
            for (CpuLoad l : after.cpus()) {
                if (touched.contains(l.cpu())) {
                    List<Task> ts = new ArrayList<>();
                    for (String n : l.tasks()) {
                        ts.add(task(n, afterContract.apply(n), after.decisions().get(n).wcetNs()));
                    }
                    base.put(l.cpu(), ts);
                }
            }
            out.add(phase(Phase.WINDOW, windowCycles, window, base, after.capacities(), test));
        }
        return out;
    }

    private static Set<Integer> cpus(List<Extra> extras) {
        Set<Integer> s = new TreeSet<>();
        for (Extra e : extras) {
            s.add(e.cpu());
        }
        return s;
    }

    private static Task task(String name, Contract c, long wcetNs) {
        return new Task(name, c.timing().periodNs(), c.timing().deadlineNs(), wcetNs, c.timing().priority());
    }

    private static final Comparator<Task> URGENT_FIRST = Comparator.comparingInt((Task t) -> -t.priority())
            .thenComparing(Task::name);

    /** One phase: every CPU a second half runs on, judged with the tasks already there. */
    private static TransientLoad phase(Phase phase, long cycles, List<Extra> extras, Map<Integer, List<Task>> base,
            Capacities caps, CpuAdmissionTest test) {
        TreeSet<String> components = new TreeSet<>();
        Map<Integer, List<Extra>> byCpu = new TreeMap<>();
        for (Extra e : extras) {
            components.add(e.component());
            byCpu.computeIfAbsent(e.cpu(), k -> new ArrayList<>()).add(e);
        }
        List<CpuLoad> loads = new ArrayList<>();
        List<String> refusals = new ArrayList<>();
        for (var entry : byCpu.entrySet()) {
            int id = entry.getKey();
            List<Extra> mine = entry.getValue();
            mine.sort(Comparator.comparing(Extra::task, URGENT_FIRST));
            List<Task> tasks = new ArrayList<>(base.getOrDefault(id, List.of()));
            tasks.sort(URGENT_FIRST);
            Capacities.Cpu cpu = caps.cpu(id).orElse(null);
            double cap = cpu == null ? 0 : cpu.utilisationCap();
            double util = 0;
            String why = cpu == null ? "cpu " + id + " is not among the capacity cpus" : null;
            CpuAdmissionTest.Cpu analysis = test.open(id);
            for (Task t : tasks) {
                util += t.utilisation();
                if (why == null) {
                    String no = analysis.test(t);
                    if (no != null) { // a test whose verdict depends on more than the tasks: fail closed
                        why = "cpu " + id + ": the tasks it runs now could not be judged again: " + no;
                    } else {
                        analysis.add(t);
                    }
                }
            }
            Extra culprit = null;
            for (Extra e : mine) {
                Task t = e.task();
                util += t.utilisation();
                tasks.add(t);
                if (why != null) {
                    continue;
                }
                if (util > cap + 1e-9) {
                    why = "cpu " + id + ": utilisation " + Text.util(util) + " with '" + t.name() + "' exceeds cap "
                            + Text.util(cap);
                } else {
                    String no = analysis.test(t);
                    if (no != null) {
                        why = "cpu " + id + ": " + no;
                    } else {
                        analysis.add(t);
                        continue;
                    }
                }
                culprit = e;
            }
            tasks.sort(URGENT_FIRST);
            List<String> names = new ArrayList<>(tasks.size());
            for (Task t : tasks) {
                names.add(t.name());
            }
            loads.add(new CpuLoad(id, cap, util, names, why == null ? analysis.proof() : TransientLoad.NOT_SCHEDULABLE));
            if (why != null) {
                Extra who = culprit != null ? culprit : mine.get(0);
                refusals.add(phrase(phase, who.component(), cyclesOf(who.cycles())) + ": " + why);
            }
        }
        return new TransientLoad(phase, cycles, List.copyOf(components), loads, refusals);
    }

    private static String cyclesOf(long cycles) {
        return cycles + (cycles == 1 ? " cycle" : " cycles");
    }

    private static String phrase(Phase phase, String component, String cycles) {
        return phase == Phase.SHADOW
                ? "update '" + component + "': its shadow run (" + cycles + ") runs the new half beside the old one"
                : "update '" + component + "': its rollback window (" + cycles + ") keeps the old half running beside "
                        + "the new one";
    }
}
