package org.arflex.planner.impl;

import java.util.ArrayList;
import java.util.Comparator;
import java.util.HashMap;
import java.util.HashSet;
import java.util.List;
import java.util.Map;
import java.util.PriorityQueue;
import java.util.Set;
import java.util.function.Function;
import org.arflex.contract.Contract;

/**
 * The order of one admission run (see {@link Admission}): the candidates' groups in dependency
 * order (a cycle of required inputs is one group), each group's effective criticality (the highest
 * of its own and its consumers'), whether it runs, and the queue of groups whose providers are all
 * decided, ranked by effective criticality (highest first), running first, then name.
 */
final class AdmissionOrder {
    final List<List<String>> groups;
    final List<Set<Integer>> consumersOf;
    final int[] eff;
    final boolean[] isRunning;
    /** Per group: how many of its provider groups are not decided yet. */
    final int[] pending;
    /** The groups whose providers are all decided, best rank first. */
    final PriorityQueue<Integer> ready;

    AdmissionOrder(Map<String, Contract> cands, Function<String, Set<String>> providersOf, Set<String> running) {
        List<List<String>> groups = Graphs.dependencyOrder(cands.keySet(), providersOf::apply);
        int g = groups.size();
        Map<String, Integer> groupOf = new HashMap<>();
        for (int i = 0; i < g; i++) {
            for (String n : groups.get(i)) {
                groupOf.put(n, i);
            }
        }
        List<Set<Integer>> consumersOf = new ArrayList<>();
        List<Set<Integer>> providersOfGroup = new ArrayList<>();
        for (int i = 0; i < g; i++) {
            consumersOf.add(new HashSet<>());
            providersOfGroup.add(new HashSet<>());
        }
        for (int i = 0; i < g; i++) {
            for (String n : groups.get(i)) {
                for (String p : providersOf.apply(n)) {
                    Integer j = groupOf.get(p);
                    if (j != null && j != i) {
                        consumersOf.get(j).add(i);
                        providersOfGroup.get(i).add(j);
                    }
                }
            }
        }
        // Effective criticality: consumers before providers (reverse dependency order).
        int[] eff = new int[g];
        boolean[] isRunning = new boolean[g];
        for (int i = g - 1; i >= 0; i--) {
            int e = Integer.MIN_VALUE;
            for (String n : groups.get(i)) {
                e = Math.max(e, cands.get(n).criticality());
                isRunning[i] |= running.contains(n);
            }
            for (int c : consumersOf.get(i)) {
                e = Math.max(e, eff[c]);
            }
            eff[i] = e;
        }
        int[] pending = new int[g];
        // Rank every group once by (effective criticality desc, running first, name); the
        // queue then compares plain ints.
        Integer[] byKey = new Integer[g];
        for (int i = 0; i < g; i++) {
            byKey[i] = i;
        }
        java.util.Arrays.sort(byKey, Comparator.comparingInt((Integer i) -> -eff[i])
                .thenComparingInt(i -> isRunning[i] ? 0 : 1).thenComparing(i -> groups.get(i).get(0)));
        int[] rank = new int[g];
        for (int k = 0; k < g; k++) {
            rank[byKey[k]] = k;
        }
        PriorityQueue<Integer> ready = new PriorityQueue<>((x, y) -> Integer.compare(rank[x], rank[y]));
        for (int i = 0; i < g; i++) {
            pending[i] = providersOfGroup.get(i).size();
            if (pending[i] == 0) {
                ready.add(i);
            }
        }
        this.groups = groups;
        this.consumersOf = consumersOf;
        this.eff = eff;
        this.isRunning = isRunning;
        this.pending = pending;
        this.ready = ready;
    }
}
