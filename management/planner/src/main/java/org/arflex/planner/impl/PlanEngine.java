package org.arflex.planner.impl;

import java.util.ArrayDeque;
import java.util.ArrayList;
import java.util.Collections;
import java.util.HashMap;
import java.util.HashSet;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import java.util.Objects;
import java.util.Optional;
import java.util.Set;
import java.util.SortedMap;
import java.util.SortedSet;
import java.util.TreeMap;
import java.util.TreeSet;
import org.arflex.contract.Contract;
import org.arflex.contract.PortSpec;
import org.arflex.planner.AdmissionResult;
import org.arflex.planner.Capacities;
import org.arflex.planner.Change;
import org.arflex.planner.CpuAdmissionTest;
import org.arflex.planner.Plan;
import org.arflex.planner.Satisfaction;
import org.arflex.planner.TransientLoad;
import org.arflex.planner.Wire;

/**
 * The engine behind {@link org.arflex.planner.Planner}: the cell as the planner sees it
 * (installed contracts, the Active set, blocked components, capacities, measured WCETs) and the
 * one function that plans a change.
 *
 * <p>A plan:
 * <ol>
 * <li>applies the contract part to the resolver (incrementally);</li>
 * <li>admits the satisfied, unblocked components against the new capacities
 * ({@link Admission}, each CPU judged by the {@link CpuAdmissionTest}); a blocked component
 * takes its dependents down as a missing provider would;</li>
 * <li>STOPs what was Active and is not admitted (uninstalled, unsatisfied, refused, blocked),
 * STARTs what is admitted and was not Active, and RESTARTs what stays Active but was replaced,
 * rewired (its input wires to Active providers changed, or a replaced provider changed the
 * port it feeds it from) or moved to another CPU;</li>
 * <li>orders stops dependents first by the old wiring and starts providers first by the new
 * wiring, a cycle as one group.</li>
 * </ol>
 *
 * <p>Not thread-safe; call from one thread (the DRCR's actor).
 */
public final class PlanEngine {

    /** How the reason of a HOLD starts: a safety input lost its provider. */
    private static final String SAFETY_LOST = "safety input ";

    private final Resolver resolver = new Resolver();
    private final TreeSet<String> active = new TreeSet<>();
    private final TreeMap<String, String> blocked = new TreeMap<>();
    private final TreeMap<String, Long> measured = new TreeMap<>();
    private final TreeMap<String, Integer> cpuOf = new TreeMap<>();
    /** Components admission refused at the last apply, with the reason (for START reasons). */
    private final TreeMap<String, String> lastRefused = new TreeMap<>();
    private final CpuAdmissionTest cpuTest;
    private Capacities capacities;
    /** Derive the plan of one install from {@link #picture} when it is provably the same. */
    private final boolean incremental;
    /** The plan of no change in the current state, once asked; null after a commit. */
    private CurrentPicture picture;
    /** How many plans {@link InstallDryRun} derived (for tests). */
    private long derived;

    /** An empty cell with these capacities, whose CPUs {@code cpuTest} judges. */
    public PlanEngine(Capacities capacities, CpuAdmissionTest cpuTest) {
        this(capacities, cpuTest, true);
    }

    /** As {@link #PlanEngine(Capacities, CpuAdmissionTest)}; {@code incremental} false always plans in full (tests). */
    PlanEngine(Capacities capacities, CpuAdmissionTest cpuTest, boolean incremental) {
        this.capacities = Objects.requireNonNull(capacities, "capacities");
        this.cpuTest = Objects.requireNonNull(cpuTest, "cpuTest");
        this.incremental = incremental;
    }

    /** How many plans were derived from the plan of no change instead of computed in full. */
    long derivedPlans() {
        return derived;
    }

    /**
     * Plans a change without applying it.
     *
     * @throws IllegalArgumentException naming the component when the change is inconsistent
     *                                  with the cell (install of an installed name, replace or
     *                                  uninstall of an unknown one, a name in two parts that
     *                                  exclude each other, block or measurement of an unknown
     *                                  one, unblock of one that is not blocked)
     */
    public Plan plan(Change change) {
        return compute(change, false);
    }

    /**
     * Plans a change with the same computation as {@link #plan(Change)} and makes its outcome
     * the new state.
     *
     * @throws IllegalArgumentException as {@link #plan(Change)}; the state is then unchanged
     */
    public Plan apply(Change change) {
        return compute(change, true);
    }

    /** The plan of the empty change: the full current picture, normally without actions. */
    public Plan current() {
        return picture().plan();
    }

    private CurrentPicture picture() {
        if (picture == null) {
            AdmissionTrace trace = new AdmissionTrace();
            Plan p = compute(Change.none(), false, trace);
            picture = new CurrentPicture(p, trace);
        }
        return picture;
    }

    /** Current capacities. */
    public Capacities capacities() {
        return capacities;
    }

    /** Current measured WCETs, ns, by name. */
    public SortedMap<String, Long> measuredWcetNs() {
        return Collections.unmodifiableSortedMap(new TreeMap<>(measured));
    }

    /** Components Active in the current state. */
    public SortedSet<String> active() {
        return Collections.unmodifiableSortedSet(new TreeSet<>(active));
    }

    /** Blocked components and why. */
    public SortedMap<String, String> blocked() {
        return Collections.unmodifiableSortedMap(new TreeMap<>(blocked));
    }

    /** CPU of every Active periodic or sporadic component. */
    public SortedMap<String, Integer> cpuAssignment() {
        return Collections.unmodifiableSortedMap(new TreeMap<>(cpuOf));
    }

    /** The installed contract of that name. */
    public Optional<Contract> contract(String name) {
        return resolver.contract(name);
    }

    /** Installed contracts, by name. */
    public List<Contract> contracts() {
        return resolver.contracts();
    }

    /**
     * Resolver satisfaction of one installed component (ignores admission and blocking).
     *
     * @throws IllegalArgumentException naming it when it is not installed
     */
    public Satisfaction satisfaction(String name) {
        return resolver.satisfaction(name);
    }

    /** All resolver wires, sorted. */
    public List<Wire> wires() {
        return resolver.wires();
    }

    // ------------------------------------------------------------------------------------------

    private Plan compute(Change change, boolean commit) {
        return compute(change, commit, null);
    }

    /** Plans in full, or derives the plan of one install (both validate first). */
    private Plan compute(Change change, boolean commit, AdmissionTrace trace) {
        Objects.requireNonNull(change, "change");
        // 1. Validate against the current state; nothing is touched before this passes.
        Map<String, Contract> puts = new LinkedHashMap<>();
        TreeSet<String> installed = new TreeSet<>();
        TreeMap<String, Contract> replaced = new TreeMap<>(); // name -> old contract
        for (Contract c : change.installs()) {
            if (resolver.contains(c.name())) {
                throw new IllegalArgumentException("install '" + c.name() + "': already installed (version "
                        + resolver.contract(c.name()).get().version() + "); use replace");
            }
            addPut(puts, c);
            installed.add(c.name());
        }
        for (Contract c : change.replaces()) {
            if (!resolver.contains(c.name())) {
                throw new IllegalArgumentException("replace '" + c.name() + "': not installed; use install");
            }
            addPut(puts, c);
            replaced.put(c.name(), resolver.contract(c.name()).get());
        }
        for (Contract c : change.puts()) {
            addPut(puts, c);
            if (resolver.contains(c.name())) {
                replaced.put(c.name(), resolver.contract(c.name()).get());
            } else {
                installed.add(c.name());
            }
        }
        TreeMap<String, Contract> uninstalled = new TreeMap<>();
        for (String n : change.uninstalls()) {
            if (!resolver.contains(n)) {
                throw new IllegalArgumentException("uninstall '" + n + "': not installed");
            }
            if (puts.containsKey(n)) {
                throw new IllegalArgumentException("component '" + n + "' is both uninstalled and installed in one change");
            }
            uninstalled.put(n, resolver.contract(n).get());
        }
        Transients.checkOverlaps(change, puts.keySet(), installed);
        // Identical replacements change nothing.
        replaced.entrySet().removeIf(e -> e.getValue().equals(puts.get(e.getKey())));
        TreeMap<String, String> newBlocked = new TreeMap<>(blocked);
        newBlocked.keySet().removeAll(uninstalled.keySet());
        for (String n : change.unblocks()) {
            if (!blocked.containsKey(n)) {
                throw new IllegalArgumentException("unblock '" + n + "': not blocked");
            }
            if (change.blocks().containsKey(n)) {
                throw new IllegalArgumentException("component '" + n + "' is both blocked and unblocked in one change");
            }
            newBlocked.remove(n);
        }
        for (var e : change.blocks().entrySet()) {
            if (!installedAfter(e.getKey(), puts, uninstalled)) {
                throw new IllegalArgumentException("block '" + e.getKey() + "': not installed");
            }
            newBlocked.put(e.getKey(), e.getValue());
        }
        TreeMap<String, Long> newMeasured = new TreeMap<>(measured);
        newMeasured.keySet().removeAll(uninstalled.keySet());
        for (var e : change.measuredWcetNs().entrySet()) {
            if (!installedAfter(e.getKey(), puts, uninstalled)) {
                throw new IllegalArgumentException("measured WCET for '" + e.getKey() + "': not installed");
            }
            if (e.getValue() == 0) {
                newMeasured.remove(e.getKey());
            } else {
                newMeasured.put(e.getKey(), e.getValue());
            }
        }
        Capacities newCaps = change.capacities().orElse(capacities);

        if (incremental && trace == null && installed.size() == 1 && puts.size() == 1 && uninstalled.isEmpty()
                && change.blocks().isEmpty() && change.unblocks().isEmpty() && change.measuredWcetNs().isEmpty()
                && change.capacities().isEmpty() && change.overlaps().isEmpty()) {
            Plan p = derive(change, puts.values().iterator().next(), commit, newBlocked, newMeasured);
            if (p != null) {
                return p;
            }
        }

        // 2. The picture before: effective input wiring of the Active components.
        Map<String, List<Wire>> oldEff = new HashMap<>();
        for (String n : active) {
            oldEff.put(n, effective(n, active));
        }
        Map<String, Contract> oldContracts = new HashMap<>();
        oldContracts.putAll(replaced);
        oldContracts.putAll(uninstalled);

        // 3. Apply the contract part; undone at the end of a dry run (or on failure).
        List<Contract> changedPuts = new ArrayList<>();
        for (Contract c : puts.values()) {
            if (!replaced.containsKey(c.name()) && !installed.contains(c.name())) {
                continue; // identical replacement
            }
            changedPuts.add(c);
        }
        resolver.apply(changedPuts, uninstalled.keySet());
        boolean done = false;
        try {
            Plan plan = build(change, installed, replaced, uninstalled, newBlocked, newMeasured, newCaps, oldEff,
                    oldContracts, trace);
            if (commit) {
                commit(plan, newBlocked, newMeasured, newCaps);
            }
            done = true;
            return plan;
        } finally {
            if (!commit || !done) {
                List<Contract> restore = new ArrayList<>();
                for (Contract c : changedPuts) {
                    if (replaced.containsKey(c.name())) {
                        restore.add(replaced.get(c.name()));
                    }
                }
                restore.addAll(uninstalled.values());
                resolver.apply(restore, installed);
            }
        }
    }

    /**
     * The plan of installing {@code x} derived from the plan of no change, or null when it may
     * differ from the full computation ({@link InstallDryRun}). Leaves the state as it was,
     * unless committing.
     */
    private Plan derive(Change change, Contract x, boolean commit, SortedMap<String, String> newBlocked,
            SortedMap<String, Long> newMeasured) {
        CurrentPicture base = picture();
        ResolveDelta delta = resolver.put(x);
        boolean keep = false;
        try {
            Plan plan;
            try {
                plan = InstallDryRun.plan(base, resolver, delta, x, change, capacities, measured, blocked.keySet(),
                        cpuTest);
            } catch (ReplayRefused e) {
                plan = null; // a test whose state the trace cannot rebuild: plan in full
            }
            if (plan != null) {
                derived++;
                if (commit) {
                    commit(plan, newBlocked, newMeasured, capacities);
                    keep = true;
                }
            }
            return plan;
        } finally {
            if (!keep) {
                resolver.remove(x.name());
            }
        }
    }

    /** Makes a plan's outcome the state. */
    private void commit(Plan plan, SortedMap<String, String> newBlocked, SortedMap<String, Long> newMeasured,
            Capacities newCaps) {
        picture = null;
        active.clear();
        active.addAll(plan.activeAfter());
        cpuOf.clear();
        cpuOf.putAll(plan.cpuAssignment());
        blocked.clear();
        blocked.putAll(newBlocked);
        measured.clear();
        measured.putAll(newMeasured);
        capacities = newCaps;
        lastRefused.clear();
        lastRefused.putAll(plan.admission().refused());
    }

    private static void addPut(Map<String, Contract> puts, Contract c) {
        if (puts.put(c.name(), c) != null) {
            throw new IllegalArgumentException("contract '" + c.name() + "' is given twice in one change");
        }
    }

    private boolean installedAfter(String n, Map<String, Contract> puts, Map<String, Contract> uninstalled) {
        return puts.containsKey(n) || (resolver.contains(n) && !uninstalled.containsKey(n));
    }

    /** Input wires of {@code n} whose provider is in {@code running}. */
    private List<Wire> effective(String n, Set<String> running) {
        List<Wire> out = new ArrayList<>();
        for (Wire w : resolver.inputWires(n)) {
            if (running.contains(w.provider())) {
                out.add(w);
            }
        }
        return out;
    }

    private Plan build(Change change, Set<String> installed, SortedMap<String, Contract> replaced,
            SortedMap<String, Contract> uninstalled, SortedMap<String, String> newBlocked,
            SortedMap<String, Long> newMeasured, Capacities newCaps, Map<String, List<Wire>> oldEff,
            Map<String, Contract> oldContracts, AdmissionTrace trace) {
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
                }
                actions.add(new Plan.Action(Plan.Op.STOP, n, why));
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
                actions.add(new Plan.Action(Plan.Op.START, n, why + "; " + admitted));
                starting.add(n);
            } else {
                List<String> why = new ArrayList<>();
                boolean rewireOnly = restartReasons(n, replaced, oldEff.get(n), newEff.get(n), oldContracts, adm, why);
                if (!why.isEmpty() && rewireOnly) {
                    boolean holds = why.stream().anyMatch(w -> w.startsWith(SAFETY_LOST));
                    actions.add(new Plan.Action(holds ? Plan.Op.HOLD : Plan.Op.REBIND, n, String.join("; ", why)));
                } else if (!why.isEmpty()) {
                    actions.add(new Plan.Action(Plan.Op.RESTART, n, String.join("; ", why)));
                    stopping.add(n);
                    starting.add(n);
                }
            }
        }

        // Order: stops dependents first by the old wiring, starts providers first by the new.
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
        return new Plan(change, title(change, installed, replaced, uninstalled, newCaps), actions, stopOrder,
                startGroups, active, target, inactive, wiring, adm, cycles, notes, transients);
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

    /**
     * Collects into {@code why} what changed for a component Active before and after; returns
     * true when only its input wires changed (same contract, same CPU, every provider port of
     * the same shape), which the DRCR applies live with UNBIND/BIND instead of a restart.
     */
    private boolean restartReasons(String n, SortedMap<String, Contract> replaced, List<Wire> oldWires,
            List<Wire> newWires, Map<String, Contract> oldContracts, AdmissionResult adm, List<String> why) {
        boolean structural = false;
        if (replaced.containsKey(n)) {
            structural = true;
            String o = replaced.get(n).version();
            String v = resolver.contract(n).get().version();
            why.add(o.equals(v) ? "contract changed (version " + v + ")" : "replaced " + o + " -> " + v);
        }
        Map<String, Wire> before = new TreeMap<>();
        for (Wire w : oldWires) {
            before.put(w.inPort(), w);
        }
        Map<String, Wire> after = new TreeMap<>();
        for (Wire w : newWires) {
            after.put(w.inPort(), w);
        }
        TreeSet<String> ports = new TreeSet<>(before.keySet());
        ports.addAll(after.keySet());
        for (String p : ports) {
            Wire b = before.get(p);
            Wire a = after.get(p);
            if (a != null && b != null && a.equals(b)) {
                Contract oldProvider = oldContracts.get(a.provider());
                if (oldProvider != null) {
                    PortSpec op = oldProvider.port(a.outPort()).orElse(null);
                    PortSpec np = resolver.contract(a.provider()).get().port(a.outPort()).orElse(null);
                    if (op != null && np != null && !samePortShape(op, np)) {
                        structural = true;
                        why.add("provider port " + a.source() + " changed (" + shape(op) + " -> " + shape(np) + ")");
                    }
                }
            } else if (a != null && b != null) {
                why.add("input '" + p + "' now from " + a.source() + " (was " + b.source() + ")");
            } else if (a != null) {
                why.add("input '" + p + "' now from " + a.source());
            } else if (resolver.contract(n).flatMap(c -> c.port(p)).map(PortSpec::safety).orElse(false)) {
                why.add(SAFETY_LOST + "'" + p + "' lost " + b.source() + ": protective stop until a guard is bound and "
                        + "the operator resets");
            } else {
                why.add("input '" + p + "' lost " + b.source());
            }
        }
        Integer oldCpu = cpuOf.get(n);
        OptionalIntBox newCpu = new OptionalIntBox(adm.cpuOf(n));
        if (oldCpu != null && newCpu.present && oldCpu != newCpu.value) {
            structural = true;
            why.add("moved cpu " + oldCpu + " -> " + newCpu.value);
        }
        return !structural;
    }

    private record OptionalIntBox(boolean present, int value) {
        OptionalIntBox(java.util.OptionalInt o) {
            this(o.isPresent(), o.isPresent() ? o.getAsInt() : -1);
        }
    }

    private static boolean samePortShape(PortSpec a, PortSpec b) {
        return a.type().equals(b.type()) && a.typeVersion().equals(b.typeVersion()) && a.method() == b.method()
                && a.depth() == b.depth() && a.overflow() == b.overflow();
    }

    private static String shape(PortSpec p) {
        return p.type() + " " + p.typeVersion() + " " + p.method().name().toLowerCase(java.util.Locale.ROOT)
                + " depth " + p.depth();
    }

    private String title(Change change, Set<String> installed, SortedMap<String, Contract> replaced,
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
