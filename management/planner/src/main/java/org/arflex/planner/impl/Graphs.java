package org.arflex.planner.impl;

import java.util.ArrayDeque;
import java.util.ArrayList;
import java.util.Collection;
import java.util.Collections;
import java.util.Comparator;
import java.util.HashMap;
import java.util.List;
import java.util.Map;
import java.util.PriorityQueue;
import java.util.Set;
import java.util.TreeSet;
import java.util.function.Function;

/** Graph algorithms over component names; iterative so that long chains do not overflow. */
public final class Graphs {

    private Graphs() {
    }

    /**
     * Strongly connected components of the nodes in {@code nodes}, following the edges that
     * {@code providers} gives (edges to names outside {@code nodes} are ignored). Each component
     * is sorted; the list is in no particular order.
     */
    @SuppressWarnings("unchecked")
    public static List<List<String>> sccs(Collection<String> nodes, Function<String, ? extends Collection<String>> providers) {
        // Iterative Tarjan. Nodes and edges are visited in sorted order for determinism.
        Set<String> all = nodes instanceof Set<?> ? (Set<String>) nodes : new java.util.HashSet<>(nodes);
        List<String> roots = new ArrayList<>(nodes);
        Collections.sort(roots);
        Map<String, Integer> index = new HashMap<>();
        Map<String, Integer> low = new HashMap<>();
        ArrayDeque<String> stack = new ArrayDeque<>();
        Set<String> onStack = new java.util.HashSet<>();
        List<List<String>> out = new ArrayList<>();
        int counter = 0;
        for (String root : roots) {
            if (index.containsKey(root)) {
                continue;
            }
            ArrayDeque<Object[]> call = new ArrayDeque<>();
            index.put(root, counter);
            low.put(root, counter);
            counter++;
            stack.push(root);
            onStack.add(root);
            call.push(new Object[] {root, succ(root, all, providers).iterator()});
            while (!call.isEmpty()) {
                Object[] frame = call.peek();
                String v = (String) frame[0];
                @SuppressWarnings("unchecked")
                java.util.Iterator<String> it = (java.util.Iterator<String>) frame[1];
                if (it.hasNext()) {
                    String w = it.next();
                    if (!index.containsKey(w)) {
                        index.put(w, counter);
                        low.put(w, counter);
                        counter++;
                        stack.push(w);
                        onStack.add(w);
                        call.push(new Object[] {w, succ(w, all, providers).iterator()});
                    } else if (onStack.contains(w)) {
                        low.put(v, Math.min(low.get(v), index.get(w)));
                    }
                } else {
                    call.pop();
                    if (!call.isEmpty()) {
                        String parent = (String) call.peek()[0];
                        low.put(parent, Math.min(low.get(parent), low.get(v)));
                    }
                    if (low.get(v).equals(index.get(v))) {
                        List<String> comp = new ArrayList<>();
                        String w;
                        do {
                            w = stack.pop();
                            onStack.remove(w);
                            comp.add(w);
                        } while (!w.equals(v));
                        Collections.sort(comp);
                        out.add(comp);
                    }
                }
            }
        }
        return out;
    }

    private static List<String> succ(String v, Set<String> all, Function<String, ? extends Collection<String>> providers) {
        Collection<String> ps = providers.apply(v);
        if (ps == null || ps.isEmpty()) {
            return List.of();
        }
        List<String> s = new ArrayList<>(ps.size());
        for (String p : ps) {
            if (all.contains(p)) {
                s.add(p);
            }
        }
        if (s.size() > 1 && !(ps instanceof java.util.SortedSet<?>)) {
            Collections.sort(s);
        }
        return s;
    }

    /** Cycles: components of more than one member, or one member that provides to itself; sorted. */
    public static List<List<String>> cycles(Map<String, ? extends Collection<String>> providers) {
        List<List<String>> out = new ArrayList<>();
        for (List<String> c : sccs(providers.keySet(), providers::get)) {
            if (c.size() > 1 || providers.get(c.get(0)).contains(c.get(0))) {
                out.add(c);
            }
        }
        out.sort(Comparator.comparing(c -> c.get(0)));
        return out;
    }

    /**
     * The strongly connected components of {@code nodes} in dependency order: every group comes
     * after the groups that provide to it; among groups ready at the same time, the one with the
     * least member name first.
     */
    public static List<List<String>> dependencyOrder(Collection<String> nodes,
            Function<String, ? extends Collection<String>> providers) {
        List<List<String>> comps = sccs(nodes, providers);
        Map<String, Integer> compOf = new HashMap<>();
        for (int i = 0; i < comps.size(); i++) {
            for (String n : comps.get(i)) {
                compOf.put(n, i);
            }
        }
        int[] pending = new int[comps.size()];
        List<List<Integer>> consumers = new ArrayList<>();
        for (int i = 0; i < comps.size(); i++) {
            consumers.add(new ArrayList<>());
        }
        for (int i = 0; i < comps.size(); i++) {
            TreeSet<Integer> provs = new TreeSet<>();
            for (String n : comps.get(i)) {
                Collection<String> ps = providers.apply(n);
                if (ps != null) {
                    for (String p : ps) {
                        Integer j = compOf.get(p);
                        if (j != null && j != i) {
                            provs.add(j);
                        }
                    }
                }
            }
            pending[i] = provs.size();
            for (int j : provs) {
                consumers.get(j).add(i);
            }
        }
        Integer[] byName = new Integer[comps.size()];
        for (int i = 0; i < byName.length; i++) {
            byName[i] = i;
        }
        java.util.Arrays.sort(byName, Comparator.comparing(i -> comps.get(i).get(0)));
        int[] rank = new int[comps.size()];
        for (int k = 0; k < byName.length; k++) {
            rank[byName[k]] = k;
        }
        PriorityQueue<Integer> ready = new PriorityQueue<>((x, y) -> Integer.compare(rank[x], rank[y]));
        for (int i = 0; i < comps.size(); i++) {
            if (pending[i] == 0) {
                ready.add(i);
            }
        }
        List<List<String>> out = new ArrayList<>();
        while (!ready.isEmpty()) {
            int i = ready.poll();
            out.add(comps.get(i));
            for (int c : consumers.get(i)) {
                if (--pending[c] == 0) {
                    ready.add(c);
                }
            }
        }
        return out;
    }
}
