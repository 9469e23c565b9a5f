package org.arflex.planner.impl;

import java.util.ArrayList;
import java.util.Collections;
import java.util.List;
import java.util.Map;
import java.util.Set;
import org.arflex.planner.Wire;

/** The order of a plan's actions: stops dependents first by the old wiring, starts providers first by the new, a cycle as one start group. */
final class StartStopOrder {
    private StartStopOrder() {
    }

    /** Who stops, dependents first ({@code oldEff}: the effective input wires before). */
    static List<String> stopOrder(Set<String> active, Map<String, List<Wire>> oldEff, Set<String> stopping) {
        List<List<String>> oldOrder = Graphs.dependencyOrder(active, n -> providers(oldEff.get(n)));
        List<String> stopOrder = new ArrayList<>();
        for (List<String> g : oldOrder) {
            for (String n : g) {
                if (stopping.contains(n)) {
                    stopOrder.add(n);
                }
            }
        }
        Collections.reverse(stopOrder);
        return stopOrder;
    }

    /** Who starts, in groups, providers first ({@code newEff}: the effective input wires after). */
    static List<List<String>> startGroups(Set<String> target, Map<String, List<Wire>> newEff, Set<String> starting) {
        List<List<String>> startGroups = new ArrayList<>();
        for (List<String> g : Graphs.dependencyOrder(target, n -> providers(newEff.get(n)))) {
            List<String> sel = new ArrayList<>();
            for (String n : g) {
                if (starting.contains(n)) {
                    sel.add(n);
                }
            }
            if (!sel.isEmpty()) {
                startGroups.add(sel);
            }
        }
        return startGroups;
    }

    private static List<String> providers(List<Wire> ws) {
        if (ws == null) {
            return List.of();
        }
        List<String> s = new ArrayList<>(ws.size());
        for (Wire w : ws) {
            s.add(w.provider());
        }
        return s;
    }
}
