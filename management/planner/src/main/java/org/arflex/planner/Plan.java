package org.arflex.planner;

import java.util.ArrayList;
import java.util.Collections;
import java.util.List;
import java.util.Optional;
import java.util.SortedMap;
import java.util.SortedSet;
import java.util.TreeMap;
import java.util.TreeSet;
import org.arflex.planner.impl.Text;

/**
 * What a {@link Change} does to the cell: the components to stop, start and restart with the
 * reason of each, the order to do it in, and the resulting wiring and CPU assignment. Immutable.
 *
 * <p>The DRCR executes a plan as follows: stop the components of {@link #stopOrder()} one by
 * one (dependents before their providers, by the wiring before the change); then for each group
 * of {@link #startGroups()} in order (providers before dependents, by the wiring after the
 * change; a group is a cycle of required inputs, or a single component), create the port
 * segments of all its members, then start them. A {@link Op#RESTART} appears in both sequences.
 * A {@link Op#REBIND} appears in neither: before the stops, unbind its inputs whose provider
 * changes or goes; after the starts, bind its inputs to their new providers ({@link
 * #wiringOf(String)}), while it keeps running. {@link #toText()} is what the {@code plan}
 * command prints.
 */
public final class Plan {

    /** What happens to one component. */
    public enum Op {
        /** Not Active before, Active after. */
        START,
        /** Active before, not Active after. */
        STOP,
        /** Active before and after, but replaced, moved, or a provider's port changed shape: stopped, then started. */
        RESTART,
        /**
         * Active before and after with the same contract and CPU; only input wires change, and
         * they are bound and unbound while it runs (no restart, so a moving component keeps
         * moving and needs no operator reset).
         */
        REBIND,
        /**
         * As {@link #REBIND}, when a safety input (contracts/SPEC.md §6.8) loses its provider:
         * the inputs are rewired while it runs, and it holds in a protective stop (its RT half
         * judges the input) until a guard is bound again and the operator resets it. Never
         * planned as a plain REBIND, so the plan and the log say that the arm stops.
         */
        HOLD
    }

    /**
     * One step of a plan.
     *
     * @param op        what happens
     * @param component the component
     * @param reason    why, in one human sentence
     */
    public record Action(Op op, String component, String reason) {
    }

    private final Change change;
    private final String title;
    private final List<Action> actions;
    private final List<String> stopOrder;
    private final List<List<String>> startGroups;
    private final SortedSet<String> activeBefore;
    private final SortedSet<String> activeAfter;
    private final SortedMap<String, String> inactiveAfter;
    private final List<Wire> wiring;
    private final AdmissionResult admission;
    private final List<List<String>> cycles;
    private final List<String> notes;
    private final List<TransientLoad> transients;

    /**
     * Creates a plan without transient loads; the {@link Planner} is its only intended author.
     *
     * @param change        the change planned
     * @param title         one-line description with versions
     * @param actions       every action (any order; kept sorted by op, then name)
     * @param stopOrder     names to stop, in execution order
     * @param startGroups   groups of names to start, in execution order
     * @param activeBefore  Active before the change
     * @param activeAfter   Active after the change
     * @param inactiveAfter installed but not Active after, with the reason
     * @param wiring        wires between components Active after
     * @param admission     the admission run behind this plan
     * @param cycles        cycles of required inputs among the components Active after
     * @param notes         remarks that are not actions (for example a measured WCET noted)
     */
    public Plan(Change change, String title, List<Action> actions, List<String> stopOrder,
            List<List<String>> startGroups, SortedSet<String> activeBefore, SortedSet<String> activeAfter,
            SortedMap<String, String> inactiveAfter, List<Wire> wiring, AdmissionResult admission,
            List<List<String>> cycles, List<String> notes) {
        this(change, title, actions, stopOrder, startGroups, activeBefore, activeAfter, inactiveAfter, wiring, admission,
                cycles, notes, List.of());
    }

    /**
     * Creates a plan; the {@link Planner} is its only intended author.
     *
     * @param change        the change planned
     * @param title         one-line description with versions
     * @param actions       every action (any order; kept sorted by op, then name)
     * @param stopOrder     names to stop, in execution order
     * @param startGroups   groups of names to start, in execution order
     * @param activeBefore  Active before the change
     * @param activeAfter   Active after the change
     * @param inactiveAfter installed but not Active after, with the reason
     * @param wiring        wires between components Active after
     * @param admission     the admission run behind this plan
     * @param cycles        cycles of required inputs among the components Active after
     * @param notes         remarks that are not actions (for example a measured WCET noted)
     * @param transients    the loads while both halves of an update run (the change's overlaps)
     */
    public Plan(Change change, String title, List<Action> actions, List<String> stopOrder,
            List<List<String>> startGroups, SortedSet<String> activeBefore, SortedSet<String> activeAfter,
            SortedMap<String, String> inactiveAfter, List<Wire> wiring, AdmissionResult admission,
            List<List<String>> cycles, List<String> notes, List<TransientLoad> transients) {
        this.change = change;
        this.title = title;
        List<Action> sorted = new ArrayList<>(actions);
        sorted.sort((a, b) -> a.op() != b.op() ? a.op().compareTo(b.op()) : a.component().compareTo(b.component()));
        this.actions = List.copyOf(sorted);
        this.stopOrder = List.copyOf(stopOrder);
        List<List<String>> groups = new ArrayList<>();
        for (List<String> g : startGroups) {
            groups.add(List.copyOf(g));
        }
        this.startGroups = List.copyOf(groups);
        this.activeBefore = Collections.unmodifiableSortedSet(new TreeSet<>(activeBefore));
        this.activeAfter = Collections.unmodifiableSortedSet(new TreeSet<>(activeAfter));
        this.inactiveAfter = Collections.unmodifiableSortedMap(new TreeMap<>(inactiveAfter));
        this.wiring = sortedDistinct(wiring);
        this.admission = admission;
        List<List<String>> cyc = new ArrayList<>();
        for (List<String> c : cycles) {
            cyc.add(List.copyOf(c));
        }
        this.cycles = List.copyOf(cyc);
        this.notes = List.copyOf(notes);
        this.transients = List.copyOf(transients);
    }

    /** The wires sorted without duplicates; in one pass when they already are. */
    private static List<Wire> sortedDistinct(List<Wire> wires) {
        for (int i = 1; i < wires.size(); i++) {
            if (wires.get(i - 1).compareTo(wires.get(i)) >= 0) {
                return List.copyOf(new TreeSet<>(wires));
            }
        }
        return List.copyOf(wires);
    }

    /** The change this plan is for. */
    public Change change() {
        return change;
    }

    /** One line: what the change is, with versions, for example {@code update x 1.0.0 -> 1.1.0}. */
    public String title() {
        return title;
    }

    /** Every action, sorted by op (START, STOP, RESTART, REBIND, HOLD) then component name. */
    public List<Action> actions() {
        return actions;
    }

    /** The STOP actions, by name. */
    public List<Action> stops() {
        return only(Op.STOP);
    }

    /** The START actions, by name. */
    public List<Action> starts() {
        return only(Op.START);
    }

    /** The RESTART actions, by name. */
    public List<Action> restarts() {
        return only(Op.RESTART);
    }

    /** The REBIND actions, by name. */
    public List<Action> rebinds() {
        return only(Op.REBIND);
    }

    /** The HOLD actions, by name. */
    public List<Action> holds() {
        return only(Op.HOLD);
    }

    /** The REBIND and HOLD actions (rewired while running), by name. */
    public List<Action> rewires() {
        return actions.stream().filter(a -> a.op() == Op.REBIND || a.op() == Op.HOLD).toList();
    }

    private List<Action> only(Op op) {
        return actions.stream().filter(a -> a.op() == op).toList();
    }

    /** The action for that component, if any. */
    public Optional<Action> action(String component) {
        return actions.stream().filter(a -> a.component().equals(component)).findFirst();
    }

    /** STOP and RESTART components, dependents before their providers. */
    public List<String> stopOrder() {
        return stopOrder;
    }

    /**
     * START and RESTART components, grouped: each group is one component or one cycle of
     * required inputs (started together after all their segments exist), providers first.
     */
    public List<List<String>> startGroups() {
        return startGroups;
    }

    /** {@link #startGroups()} flattened. */
    public List<String> startOrder() {
        List<String> all = new ArrayList<>();
        startGroups.forEach(all::addAll);
        return Collections.unmodifiableList(all);
    }

    /** Components Active before the change. */
    public SortedSet<String> activeBefore() {
        return activeBefore;
    }

    /** Components Active once the plan is executed. */
    public SortedSet<String> activeAfter() {
        return activeAfter;
    }

    /** Installed components that are not Active after the plan, with the reason. */
    public SortedMap<String, String> inactiveAfter() {
        return inactiveAfter;
    }

    /** The wires between components Active after the plan, sorted. */
    public List<Wire> wiring() {
        return wiring;
    }

    /** The input wires of one component after the plan. */
    public List<Wire> wiringOf(String consumer) {
        return wiring.stream().filter(w -> w.consumer().equals(consumer)).toList();
    }

    /** CPU of every periodic or sporadic component Active after the plan. */
    public SortedMap<String, Integer> cpuAssignment() {
        return admission.cpuAssignment();
    }

    /** The admission run behind this plan (decisions, CPU loads, budgets). */
    public AdmissionResult admission() {
        return admission;
    }

    /** Cycles of required inputs among the components Active after: members sorted, by first member. */
    public List<List<String>> cycles() {
        return cycles;
    }

    /** Remarks that are not actions. */
    public List<String> notes() {
        return notes;
    }

    /**
     * The CPU loads while both halves of an update run (docs/DECISIONS.md D51): the shadow phase,
     * then the window phase, each only when the change's {@link Change#overlaps() overlaps} put a
     * second half on some CPU in it. Empty for a change without overlaps.
     */
    public List<TransientLoad> transients() {
        return transients;
    }

    /**
     * Why a phase of {@link #transients()} is not schedulable, one sentence per CPU, naming the
     * update, the phase, the CPU and the figures; empty when every phase fits. The final cell of
     * the plan may be admitted all the same: whoever runs both halves refuses the change.
     */
    public List<String> transientRefusals() {
        List<String> all = new ArrayList<>();
        for (TransientLoad t : transients) {
            all.addAll(t.refusals());
        }
        return Collections.unmodifiableList(all);
    }

    /** True when the plan starts, stops and restarts nothing. */
    public boolean isEmpty() {
        return actions.isEmpty();
    }

    /**
     * The text the Gogo {@code plan} command prints. The layout is stable (tests compare it):
     *
     * <pre>
     * plan: install sampler 1.0.0
     * actions:
     *   START    sample-scaler  now satisfied (x &lt;- sampler.out); cpu 1: hyperbolic bound holds (U=0.20)
     *   START    sampler        installed; cpu 0: hyperbolic bound holds (U=0.30)
     * stop order: (none)
     * start order: sampler, sample-scaler
     * wiring:
     *   sample-scaler.x &lt;- sampler.out
     * cpus:
     *   cpu 0  U=0.30/0.90  hyperbolic bound  sampler
     *   cpu 1  U=0.20/0.90  hyperbolic bound  sample-scaler
     * memory: 65 MiB of 512 MiB; network: 0 B/s of 10 MB/s
     * not active:
     *   foo  input 'x' of 'foo': no provider of arflex.Pose 1.x (state)
     * </pre>
     *
     * Sections {@code cycles:}, {@code not active:} and {@code notes:} appear only when not empty.
     * When both halves of an update run for a while ({@link #transients()}), each CPU a second
     * half runs on has one more line per phase under its own, for example
     * {@code    shadow (200 cycles)  U=0.60/0.90  hyperbolic bound  sampler, sampler (new)}, and a
     * phase that is not schedulable is said in a last section,
     * {@code not schedulable while both halves run:}.
     * </pre>
     */
    public String toText() {
        StringBuilder sb = new StringBuilder();
        sb.append("plan: ").append(title).append('\n');
        sb.append("actions:");
        if (actions.isEmpty()) {
            sb.append(" none\n");
        } else {
            sb.append('\n');
            int w = 0;
            for (Action a : actions) {
                w = Math.max(w, a.component().length());
            }
            for (Action a : actions) {
                sb.append("  ").append(pad(a.op().name(), 8)).append(' ').append(pad(a.component(), w))
                        .append("  ").append(a.reason()).append('\n');
            }
        }
        sb.append("stop order: ").append(stopOrder.isEmpty() ? "(none)" : String.join(", ", stopOrder)).append('\n');
        List<String> groups = new ArrayList<>();
        for (List<String> g : startGroups) {
            groups.add(g.size() == 1 ? g.get(0) : "{" + String.join(", ", g) + "}");
        }
        sb.append("start order: ").append(groups.isEmpty() ? "(none)" : String.join(", ", groups)).append('\n');
        sb.append("wiring:");
        if (wiring.isEmpty()) {
            sb.append(" none\n");
        } else {
            sb.append('\n');
            for (Wire wire : wiring) {
                sb.append("  ").append(wire).append('\n');
            }
        }
        if (!cycles.isEmpty()) {
            sb.append("cycles:\n");
            for (List<String> c : cycles) {
                sb.append("  {").append(String.join(", ", c)).append("}\n");
            }
        }
        sb.append("cpus:");
        if (admission.cpus().isEmpty()) {
            sb.append(" none\n");
        } else {
            sb.append('\n');
            for (CpuLoad l : admission.cpus()) {
                sb.append("  cpu ").append(l.cpu()).append("  U=").append(Text.util(l.utilisation())).append('/')
                        .append(Text.util(l.utilisationCap())).append("  ").append(l.test());
                if (!l.tasks().isEmpty()) {
                    sb.append("  ").append(String.join(", ", l.tasks()));
                }
                sb.append('\n');
                for (TransientLoad t : transients) {
                    for (CpuLoad x : t.cpus()) {
                        if (x.cpu() == l.cpu()) {
                            sb.append("    ").append(t.phase().label()).append(" (").append(t.cycles())
                                    .append(t.cycles() == 1 ? " cycle)" : " cycles)").append("  U=")
                                    .append(Text.util(x.utilisation())).append('/').append(Text.util(x.utilisationCap()))
                                    .append("  ").append(x.test()).append("  ").append(String.join(", ", x.tasks()))
                                    .append('\n');
                        }
                    }
                }
            }
        }
        Capacities caps = admission.capacities();
        sb.append("memory: ").append(Text.bytes(admission.memoryUsedBytes())).append(" of ")
                .append(Text.bytes(caps.memoryBytes())).append("; network: ").append(Text.rate(admission.networkUsedBps()))
                .append(" of ").append(Text.rate(caps.networkBps())).append('\n');
        if (!inactiveAfter.isEmpty()) {
            sb.append("not active:\n");
            int w = 0;
            for (String n : inactiveAfter.keySet()) {
                w = Math.max(w, n.length());
            }
            for (var e : inactiveAfter.entrySet()) {
                sb.append("  ").append(pad(e.getKey(), w)).append("  ").append(e.getValue()).append('\n');
            }
        }
        if (!notes.isEmpty()) {
            sb.append("notes:\n");
            for (String n : notes) {
                sb.append("  ").append(n).append('\n');
            }
        }
        List<String> refusals = transientRefusals();
        if (!refusals.isEmpty()) {
            sb.append("not schedulable while both halves run:\n");
            for (String r : refusals) {
                sb.append("  ").append(r).append('\n');
            }
        }
        return sb.toString();
    }

    private static String pad(String s, int w) {
        return s.length() >= w ? s : s + " ".repeat(w - s.length());
    }

    @Override
    public String toString() {
        return toText();
    }
}
