package org.arflex.planner.impl;

import java.util.ArrayDeque;
import java.util.ArrayList;
import java.util.HashMap;
import java.util.HashSet;
import java.util.List;
import java.util.Map;
import java.util.Set;
import java.util.SortedMap;
import java.util.TreeMap;
import java.util.TreeSet;
import org.arflex.contract.Contract;
import org.arflex.planner.AdmissionResult;
import org.arflex.planner.Capacities;
import org.arflex.planner.Change;
import org.arflex.planner.CpuAdmissionTest;
import org.arflex.planner.Plan;
import org.arflex.planner.TransientLoad;
import org.arflex.planner.Wire;

/**
 * The full computation of a plan over the engine's state (the resolver already holds the change's
 * contracts): the candidates (satisfied, not blocked, not fed by a blocked one), their admission,
 * the actions (STOP, START, RESTART, REBIND, HOLD) with their reasons, their order, the wiring, the
 * cycles and the loads while both halves of an update run.
 */
final class FullPlan {
    private final Resolver resolver;
    private final TreeSet<String> active;
    private final TreeMap<String, Long> measured;
    private final TreeMap<String, Integer> cpuOf;
    private final TreeMap<String, String> lastRefused;
    private final CpuAdmissionTest cpuTest;
    private final RestartReasons restartReasons;

    /** Over the engine's state: read at every build, never written. */
    FullPlan(Resolver resolver, TreeSet<String> active, TreeMap<String, Long> measured, TreeMap<String, Integer> cpuOf,
            TreeMap<String, String> lastRefused, CpuAdmissionTest cpuTest) {
        this.resolver = resolver;
        this.active = active;
        this.measured = measured;
        this.cpuOf = cpuOf;
        this.lastRefused = lastRefused;
        this.cpuTest = cpuTest;
        this.restartReasons = new RestartReasons(resolver, cpuOf);
    }

    /** Input wires of {@code n} whose provider is in {@code running}. */
    List<Wire> effective(String n, Set<String> running) {
        List<Wire> out = new ArrayList<>();
        for (Wire w : resolver.inputWires(n)) {
            if (running.contains(w.provider())) {
                out.add(w);
            }
        }
        return out;
    }

    Plan build(Change change, Set<String> installed, SortedMap<String, Contract> replaced,
            SortedMap<String, Contract> uninstalled, SortedMap<String, String> newBlocked,
            SortedMap<String, Long> newMeasured, Capacities newCaps, Map<String, List<Wire>> oldEff,
            Map<String, Contract> oldContracts, AdmissionTrace trace, Capacities capacities) {
        // Candidates: satisfied, not blocked, and not depending (required) on a blocked one.
        TreeMap<String, String> inactive = new TreeMap<>();
        Set<String> cands = new HashSet<>(resolver.satisfied());
        ArrayDeque<String> down = new ArrayDeque<>();
        for (var e : newBlocked.entrySet()) {
            if (cands.remove(e.getKey())) {
                down.add(e.getKey());
            }
            inactive.put(e.getKey(), "blocked: " + e.getValue());
        }
        while (!down.isEmpty()) {
            String p = down.poll();
            for (Wire w : resolver.outputWires(p)) {
                if (!resolver.isOptionalInput(w.consumer(), w.inPort()) && cands.remove(w.consumer())) {
                    inactive.put(w.consumer(), "input '" + w.inPort() + "' of '" + w.consumer() + "': provider '" + p
                            + "' is " + (newBlocked.containsKey(p) ? "blocked" : "not running"));
                    down.add(w.consumer());
                }
            }
        }
        List<Contract> candContracts = new ArrayList<>();
        for (String n : new TreeSet<>(cands)) {
            candContracts.add(resolver.contract(n).get());
        }
        Map<String, Integer> prevCpu = new HashMap<>();
        for (var e : cpuOf.entrySet()) {
            if (cands.contains(e.getKey())) {
                prevCpu.put(e.getKey(), e.getValue());
            }
        }
        AdmissionResult adm = Admission.admit(candContracts, resolver.wiresUnsorted(), newCaps, newMeasured, prevCpu, active,
                cpuTest, trace);
        TreeSet<String> target = new TreeSet<>(adm.admitted());
        inactive.putAll(adm.refused());
        for (String n : resolver.names()) {
            if (!target.contains(n) && !inactive.containsKey(n)) {
                inactive.put(n, resolver.satisfaction(n).summary());
            }
        }

        // Actions.
        List<Plan.Action> actions = new ArrayList<>();
        Map<String, List<Wire>> newEff = new HashMap<>();
        for (String n : target) {
            newEff.put(n, effective(n, target));
        }
        TreeSet<String> all = new TreeSet<>(active);
        all.addAll(target);
        TreeSet<String> stopping = new TreeSet<>();
        TreeSet<String> starting = new TreeSet<>();
        for (String n : all) {
            boolean before = active.contains(n);
            boolean after = target.contains(n);
            if (before && !after) {
                String why;
                if (uninstalled.containsKey(n)) {
                    why = "uninstalled";
                } else if (replaced.containsKey(n)) {
                    why = "replaced by " + resolver.contract(n).get().version() + ", which cannot run: " + inactive.get(n);
                } else {
                    why = inactive.get(n);
                    if (change.cause().isPresent()) {
                        // the component stops because of this change's cause: its reason says so
                        inactive.put(n, why + "; " + change.cause().get());
                    }
                }
                actions.add(new Plan.Action(Plan.Op.STOP, n, because(change, why)));
                stopping.add(n);
            } else if (!before && after) {
                String admitted = adm.decisions().get(n).reason();
                String why;
                if (installed.contains(n)) {
                    why = "installed";
                } else if (replaced.containsKey(n)) {
                    why = "replaced " + replaced.get(n).version() + " -> " + resolver.contract(n).get().version();
                } else if (change.unblocks().contains(n)) {
                    why = "unblocked";
                } else if (lastRefused.containsKey(n)) {
                    why = "admitted now (was refused: " + lastRefused.get(n) + ")";
                } else {
                    List<String> ins = new ArrayList<>();
                    for (Wire w : newEff.get(n)) {
                        ins.add(w.inPort() + " <- " + w.source());
                    }
                    why = ins.isEmpty() ? "now admitted" : "now satisfied (" + String.join(", ", ins) + ")";
                }
                actions.add(new Plan.Action(Plan.Op.START, n, because(change, why + "; " + admitted)));
                starting.add(n);
            } else {
                List<String> why = new ArrayList<>();
                boolean rewireOnly = restartReasons.collect(n, replaced, oldEff.get(n), newEff.get(n), oldContracts, adm, why);
                if (!why.isEmpty() && rewireOnly) {
                    boolean holds = why.stream().anyMatch(w -> w.startsWith(RestartReasons.SAFETY_LOST));
                    actions.add(new Plan.Action(holds ? Plan.Op.HOLD : Plan.Op.REBIND, n, because(change, String.join("; ", why))));
                } else if (!why.isEmpty()) {
                    actions.add(new Plan.Action(Plan.Op.RESTART, n, because(change, String.join("; ", why))));
                    stopping.add(n);
                    starting.add(n);
                }
            }
        }

        // Order: stops dependents first by the old wiring, starts providers first by the new.
        List<String> stopOrder = StartStopOrder.stopOrder(active, oldEff, stopping);
        List<List<String>> startGroups = StartStopOrder.startGroups(target, newEff, starting);
        List<Wire> wiring = new ArrayList<>();
        for (List<Wire> ws : newEff.values()) {
            wiring.addAll(ws);
        }
        Map<String, Set<String>> req = new HashMap<>();
        for (String n : target) {
            Set<String> ps = new TreeSet<>(resolver.requiredProviders(n));
            ps.retainAll(target);
            req.put(n, ps);
        }
        List<List<String>> cycles = Graphs.cycles(req);
        List<String> notes = new ArrayList<>();
        for (List<String> c : cycles) {
            notes.add("cycle {" + String.join(", ", c) + "}: its port segments are created before any member starts");
        }
        // While both halves of an update run (D51): counted only when the change says so.
        List<TransientLoad> transients = change.overlaps().isEmpty() ? List.of()
                : Transients.of(change, cpuOf, n -> oldContracts.containsKey(n) ? oldContracts.get(n)
                        : resolver.contract(n).orElseThrow(), measured, capacities, adm,
                        n -> resolver.contract(n).orElseThrow(), cpuTest);
        return new Plan(change, PlanTitle.of(resolver, capacities, change, installed, replaced, uninstalled, newCaps), actions, stopOrder,
                startGroups, active, target, inactive, wiring, adm, cycles, notes, transients);
    }

    /** A reason with the change's cause appended, when it has one. */
    private static String because(Change change, String why) {
        return change.cause().map(c -> why + "; " + c).orElse(why);
    }
}
