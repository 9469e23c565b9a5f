package org.arflex.planner.impl;

import java.util.ArrayList;
import java.util.Collection;
import java.util.Collections;
import java.util.HashMap;
import java.util.HashSet;
import java.util.List;
import java.util.Map;
import java.util.Optional;
import java.util.Set;
import java.util.SortedSet;
import java.util.TreeSet;
import org.arflex.contract.Contract;
import org.arflex.planner.Satisfaction;
import org.arflex.planner.Wire;

/**
 * Incremental resolver: matches every input of the installed contracts to at most one output
 * and computes which components are satisfied.
 *
 * <p><b>Matching.</b> An output {@code p.o} can feed input {@code c.i} when the port type names
 * are equal, {@code o}'s type version {@link org.arflex.contract.TypeVersion#canFeed can feed}
 * {@code i}'s, the methods are equal and the binding rule of {@code i} accepts {@code p.o}: an
 * explicit {@code component.port} accepts exactly that port (it may name the consumer itself: a
 * self-binding); a filter (RFC 1960) accepts outputs of providers whose
 * {@link Contract#attributes()} match it; no rule accepts any provider. Without an explicit rule
 * a component never feeds itself. Exactly one candidate gives a wire; none is a missing provider,
 * several are an ambiguity, both reported by name.
 *
 * <p><b>Satisfaction</b> is the greatest fixpoint of: a component is satisfied when every
 * required (non-optional) input has a wire and the wire's provider is satisfied. Cycles through
 * required inputs are therefore legal (control loops): a cycle is satisfied as a whole when
 * nothing it needs from outside is missing. Optional inputs are wired when they can be but never
 * block.
 *
 * <p><b>Incrementality.</b> Outputs are indexed by port type and inputs by port type, and every
 * provider knows the inputs it is a candidate for: a change re-matches only the inputs of the
 * changed port types and re-evaluates satisfaction only where it can change (what went down is
 * propagated to satisfied dependents; what may come up is re-solved over the unsatisfied region
 * downstream of it). {@link ResolveDelta#touched()} counts the components examined. Results are
 * equal to a resolve from scratch of the same contracts.
 *
 * <p>Not thread-safe.
 */
public final class Resolver {

    private final ResolverIndex index = new ResolverIndex();
    private final Map<String, ResolverNode> nodes = index.nodes;
    private final SatisfactionFixpoint fixpoint = new SatisfactionFixpoint(index);
    private final SatisfactionReport report = new SatisfactionReport(index);

    /** An empty resolver. */
    public Resolver() {
    }

    /**
     * Adds a contract, or replaces the installed contract of the same name (an identical
     * contract changes nothing).
     *
     * @return what changed
     */
    public ResolveDelta put(Contract contract) {
        return apply(List.of(contract), List.of());
    }

    /**
     * Removes a component.
     *
     * @throws IllegalArgumentException naming it when it is not installed
     */
    public ResolveDelta remove(String name) {
        return apply(List.of(), List.of(name));
    }

    /**
     * Applies several puts and removes as one change with one delta (removes first).
     *
     * @throws IllegalArgumentException naming the first name removed that is not installed, a
     *                                  name given twice, or a name both removed and put; nothing
     *                                  is changed then
     */
    public ResolveDelta apply(Collection<Contract> puts, Collection<String> removes) {
        Set<String> seen = new HashSet<>();
        for (String r : removes) {
            if (!nodes.containsKey(r)) {
                throw new IllegalArgumentException("cannot remove '" + r + "': not installed");
            }
            if (!seen.add(r)) {
                throw new IllegalArgumentException("component '" + r + "' is removed twice in one change");
            }
        }
        Set<String> putNames = new HashSet<>();
        for (Contract c : puts) {
            if (!putNames.add(c.name())) {
                throw new IllegalArgumentException("contract '" + c.name() + "' is given twice in one change");
            }
            if (seen.contains(c.name())) {
                throw new IllegalArgumentException("component '" + c.name() + "' is both removed and put in one change");
            }
        }
        ResolverChange ch = new ResolverChange();
        for (String r : removes) {
            ch.prevStatus.putIfAbsent(r, nodes.get(r).satisfied);
            index.detach(r, ch);
            ch.removed.add(r);
        }
        for (Contract c : puts) {
            ResolverNode old = nodes.get(c.name());
            if (old != null) {
                if (old.contract.equals(c)) {
                    continue;
                }
                ch.prevStatus.putIfAbsent(c.name(), old.satisfied);
                index.detach(c.name(), ch);
                ch.replaced.add(c.name());
                // Start from the old status: if it still holds, nothing downstream is disturbed.
                index.attach(c, ch).satisfied = old.satisfied;
            } else {
                ch.added.add(c.name());
                index.attach(c, ch);
            }
        }
        report.changed();
        return fixpoint.finish(ch);
    }

    /** The installed contract of that name. */
    public Optional<Contract> contract(String name) {
        ResolverNode n = nodes.get(name);
        return n == null ? Optional.empty() : Optional.of(n.contract);
    }

    /** All installed contracts, by name. */
    public List<Contract> contracts() {
        List<Contract> out = new ArrayList<>();
        for (String n : names()) {
            out.add(nodes.get(n).contract);
        }
        return Collections.unmodifiableList(out);
    }

    /** Installed component names, sorted. */
    public SortedSet<String> names() {
        return Collections.unmodifiableSortedSet(new TreeSet<>(nodes.keySet()));
    }

    /** Number of installed components. */
    public int size() {
        return nodes.size();
    }

    /** True when a component of that name is installed. */
    public boolean contains(String name) {
        return nodes.containsKey(name);
    }

    /** Every wire, in no particular order (for callers that sort or index themselves). */
    List<Wire> wiresUnsorted() {
        List<Wire> out = new ArrayList<>();
        for (ResolverNode n : nodes.values()) {
            for (ResolverIn in : n.inputs) {
                if (in.wire != null) {
                    out.add(in.wire);
                }
            }
        }
        return out;
    }

    /** Every wire, sorted (whether or not its ends are satisfied). */
    public List<Wire> wires() {
        List<Wire> out = new ArrayList<>();
        for (ResolverNode n : nodes.values()) {
            for (ResolverIn in : n.inputs) {
                if (in.wire != null) {
                    out.add(in.wire);
                }
            }
        }
        Collections.sort(out);
        return Collections.unmodifiableList(out);
    }

    /** The wires into the inputs of {@code consumer}, sorted; empty when not installed. */
    public List<Wire> inputWires(String consumer) {
        ResolverNode n = nodes.get(consumer);
        if (n == null) {
            return List.of();
        }
        List<Wire> out = new ArrayList<>();
        for (ResolverIn in : n.inputs) {
            if (in.wire != null) {
                out.add(in.wire);
            }
        }
        Collections.sort(out);
        return Collections.unmodifiableList(out);
    }

    /** The wires out of the outputs of {@code provider}, sorted; empty when not installed. */
    public List<Wire> outputWires(String provider) {
        Set<ResolverIn> fed = index.fedBy(provider);
        if (fed == null) {
            return List.of();
        }
        List<Wire> out = new ArrayList<>();
        for (ResolverIn in : fed) {
            if (in.wire != null && in.wire.provider().equals(provider)) {
                out.add(in.wire);
            }
        }
        Collections.sort(out);
        return Collections.unmodifiableList(out);
    }

    /** Components with a wire (required or optional) from {@code provider}, sorted. */
    public SortedSet<String> dependents(String provider) {
        TreeSet<String> s = new TreeSet<>();
        for (Wire w : outputWires(provider)) {
            s.add(w.consumer());
        }
        return Collections.unmodifiableSortedSet(s);
    }

    /** True when the component is installed and satisfied. */
    public boolean isSatisfied(String name) {
        ResolverNode n = nodes.get(name);
        return n != null && n.satisfied;
    }

    /** Satisfied component names, sorted. */
    public SortedSet<String> satisfied() {
        TreeSet<String> s = new TreeSet<>();
        for (ResolverNode n : nodes.values()) {
            if (n.satisfied) {
                s.add(n.name());
            }
        }
        return Collections.unmodifiableSortedSet(s);
    }

    /** True when the input of that component is optional (false when unknown). */
    public boolean isOptionalInput(String consumer, String inPort) {
        ResolverNode n = nodes.get(consumer);
        if (n == null) {
            return false;
        }
        for (ResolverIn in : n.inputs) {
            if (in.spec.name().equals(inPort)) {
                return in.spec.optional();
            }
        }
        return false;
    }

    /** Names of the components {@code name} requires (providers of its wired required inputs). */
    public Set<String> requiredProviders(String name) {
        return index.requiredProviders(name);
    }

    /**
     * Satisfaction of one component with its reasons and notes.
     *
     * @throws IllegalArgumentException naming it when it is not installed
     */
    public Satisfaction satisfaction(String name) {
        return report.satisfaction(name);
    }

    /**
     * Cycles through wires of required inputs: each strongly connected component of more than
     * one member, or a single member bound to itself, as its names sorted; the list sorted by
     * first name.
     */
    public List<List<String>> cycles() {
        Map<String, Set<String>> edges = new HashMap<>();
        for (ResolverNode n : nodes.values()) {
            edges.put(n.name(), requiredProviders(n.name()));
        }
        return Graphs.cycles(edges);
    }
}
