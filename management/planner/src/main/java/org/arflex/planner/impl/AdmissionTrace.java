package org.arflex.planner.impl;

import java.util.ArrayList;
import java.util.Collections;
import java.util.HashMap;
import java.util.List;
import java.util.Map;
import java.util.TreeMap;
import org.arflex.planner.AdmissionResult;
import org.arflex.planner.CpuAdmissionTest.Task;

/**
 * What one full admission run did, step by step, so that a later run over the same candidates
 * plus one new component can be derived from it ({@link InstallDryRun}): the groups in the
 * order they were admitted with the key that ordered them, the budgets used before each, what
 * each member went through (budget check, CPU choice, first try on its previous CPU), and the
 * tasks added to each CPU in order (net of the adds undone for a refused cycle).
 */
final class AdmissionTrace {

    /** One member of a group, as the run placed it. */
    static final class Member {
        final String name;
        final int step;
        final long mem;
        final long net;
        /** Budgets used when it was placed (valid when {@link #budgetChecked}). */
        long memBefore;
        long netBefore;
        /** It went through the memory and network check. */
        boolean budgetChecked;
        /** It was refused by that check. */
        boolean budgetRefused;
        /** Allowed CPU ids when it got to choosing a CPU, else null. */
        int[] allowed;
        /** Placed on its previous CPU, the first one tried. */
        boolean prevFirst;
        /** CPU chosen, -1 when none. */
        int cpu = -1;

        Member(String name, int step, long mem, long net) {
            this.name = name;
            this.step = step;
            this.mem = mem;
            this.net = net;
        }

        boolean mayUse(int cpuId) {
            if (allowed == null) {
                return false;
            }
            for (int a : allowed) {
                if (a == cpuId) {
                    return true;
                }
            }
            return false;
        }
    }

    /** One group (a component, or a cycle admitted or refused as a whole). */
    record Step(int index, int effectiveCriticality, boolean running, String firstName, List<Member> members,
            long memBefore, long netBefore) {
    }

    /** A task added to a CPU, with the step that added it. */
    record Add(int step, Task task) {
    }

    private final List<Step> steps = new ArrayList<>();
    private final Map<String, Member> members = new HashMap<>();
    private final Map<String, Integer> effective = new HashMap<>();
    private final TreeMap<Integer, List<Add>> adds = new TreeMap<>();
    private boolean anyExclusive;
    private AdmissionResult result;

    // -- recording (AdmissionRun) ------------------------------------------------------------

    Step beginStep(int eff, boolean running, List<String> names, long memBefore, long netBefore) {
        Step s = new Step(steps.size(), eff, running, names.get(0), new ArrayList<>(), memBefore, netBefore);
        steps.add(s);
        for (String n : names) {
            effective.put(n, eff);
        }
        return s;
    }

    Member member(Step s, String name, long mem, long net) {
        Member m = new Member(name, s.index(), mem, net);
        s.members().add(m);
        members.put(name, m);
        return m;
    }

    void added(int cpu, int step, Task t) {
        adds.computeIfAbsent(cpu, k -> new ArrayList<>()).add(new Add(step, t));
    }

    /** Undoes the last {@link #added} on that CPU (a refused cycle). */
    void removedLast(int cpu) {
        List<Add> l = adds.get(cpu);
        l.remove(l.size() - 1);
    }

    void exclusiveCandidate() {
        anyExclusive = true;
    }

    void finish(AdmissionResult r) {
        this.result = r;
    }

    // -- reading ------------------------------------------------------------------------------

    List<Step> steps() {
        return Collections.unmodifiableList(steps);
    }

    AdmissionResult result() {
        return result;
    }

    boolean anyExclusive() {
        return anyExclusive;
    }

    /** The trace of a candidate, or null when it was none. */
    Member member(String name) {
        return members.get(name);
    }

    /** Effective criticality of a candidate's group (provider inheritance included). */
    int effectiveCriticality(String name) {
        return effective.get(name);
    }

    /** Tasks added to that CPU in order (empty when none). */
    List<Add> adds(int cpu) {
        return adds.getOrDefault(cpu, List.of());
    }

    /** Memory used once every step ran. */
    long memUsed() {
        return result.memoryUsedBytes();
    }

    /** Network used once every step ran. */
    long netUsed() {
        return result.networkUsedBps();
    }
}
