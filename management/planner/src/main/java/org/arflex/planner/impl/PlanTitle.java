package org.arflex.planner.impl;

import java.util.ArrayList;
import java.util.List;
import java.util.Set;
import java.util.SortedMap;
import org.arflex.contract.Contract;
import org.arflex.planner.Capacities;
import org.arflex.planner.Change;

/** The title of a plan: what its change installs, updates, uninstalls, blocks, unblocks, measures and changes in the capacities. */
final class PlanTitle {
    private PlanTitle() {
    }

    static String of(Resolver resolver, Capacities capacities, Change change, Set<String> installed, SortedMap<String, Contract> replaced,
            SortedMap<String, Contract> uninstalled, Capacities newCaps) {
        List<String> parts = new ArrayList<>();
        if (!installed.isEmpty()) {
            List<String> s = new ArrayList<>();
            for (String n : installed) {
                s.add(n + " " + resolver.contract(n).get().version());
            }
            parts.add("install " + String.join(", ", s));
        }
        if (!replaced.isEmpty()) {
            List<String> s = new ArrayList<>();
            for (var e : replaced.entrySet()) {
                s.add(e.getKey() + " " + e.getValue().version() + " -> " + resolver.contract(e.getKey()).get().version());
            }
            parts.add("update " + String.join(", ", s));
        }
        if (!uninstalled.isEmpty()) {
            List<String> s = new ArrayList<>();
            for (var e : uninstalled.entrySet()) {
                s.add(e.getKey() + " " + e.getValue().version());
            }
            parts.add("uninstall " + String.join(", ", s));
        }
        if (change.capacities().isPresent()) {
            parts.add("capacities " + capacityDiff(capacities, newCaps));
        }
        change.cause().ifPresent(c -> parts.add("because " + c));
        if (!change.measuredWcetNs().isEmpty()) {
            List<String> s = new ArrayList<>();
            change.measuredWcetNs().forEach((n, w) -> s.add(n + " " + (w == 0 ? "cleared" : Text.duration(w))));
            parts.add("measured WCET " + String.join(", ", s));
        }
        if (!change.blocks().isEmpty()) {
            List<String> s = new ArrayList<>();
            change.blocks().forEach((n, r) -> s.add(n + " (" + r + ")"));
            parts.add("block " + String.join(", ", s));
        }
        if (!change.unblocks().isEmpty()) {
            parts.add("unblock " + String.join(", ", change.unblocks()));
        }
        return parts.isEmpty() ? "no change" : String.join("; ", parts);
    }

    private static String capacityDiff(Capacities a, Capacities b) {
        List<String> s = new ArrayList<>();
        if (!a.cpus().equals(b.cpus())) {
            s.add("cpus " + cpus(a) + " -> " + cpus(b));
        }
        if (a.memoryBytes() != b.memoryBytes()) {
            s.add("memory " + Text.bytes(a.memoryBytes()) + " -> " + Text.bytes(b.memoryBytes()));
        }
        if (a.networkBps() != b.networkBps()) {
            s.add("network " + Text.rate(a.networkBps()) + " -> " + Text.rate(b.networkBps()));
        }
        return s.isEmpty() ? "unchanged" : String.join(", ", s);
    }

    private static String cpus(Capacities c) {
        List<String> s = new ArrayList<>();
        for (Capacities.Cpu cpu : c.cpus()) {
            s.add(cpu.id() + "(" + Text.trim(cpu.utilisationCap()) + (cpu.reserved() ? ", reserved" : "") + ")");
        }
        return s.isEmpty() ? "none" : String.join(" ", s);
    }
}
