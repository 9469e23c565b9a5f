package org.arflex.planner.impl;

import java.util.ArrayDeque;
import java.util.ArrayList;
import java.util.Collection;
import java.util.Collections;
import java.util.HashMap;
import java.util.HashSet;
import java.util.LinkedHashSet;
import java.util.List;
import java.util.Map;
import java.util.Optional;
import java.util.Set;
import java.util.SortedSet;
import java.util.TreeMap;
import java.util.TreeSet;
import org.arflex.contract.Binding;
import org.arflex.contract.Contract;
import org.arflex.contract.PortSpec;
import org.arflex.planner.impl.LdapFilter;
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

    /** An output of an installed component. */
    private record Out(String component, PortSpec spec) implements Comparable<Out> {
        String ref() {
            return component + "." + spec.name();
        }

        @Override
        public int compareTo(Out o) {
            int c = component.compareTo(o.component);
            return c != 0 ? c : spec.name().compareTo(o.spec.name());
        }
    }

    /** An input of an installed component with its candidate providers. */
    private static final class In {
        final String consumer;
        final PortSpec spec;
        final Optional<Binding> binding;
        final LdapFilter filter;
        final String filterError;
        final TreeSet<Out> candidates = new TreeSet<>();
        Wire wire;
        /** The node of {@link #wire}'s provider (refreshed by every rewire), null without wire. */
        Node providerNode;
        /** The node that owns this input. */
        Node owner;
        /** The index set this input is registered in, if any. */
        Set<In> home;

        In(String consumer, PortSpec spec) {
            this.consumer = consumer;
            this.spec = spec;
            this.binding = spec.binding();
            LdapFilter f = null;
            String err = null;
            Optional<String> text = binding.flatMap(Binding::filter);
            if (text.isPresent() && binding.get().component().isEmpty()) {
                try {
                    f = LdapFilter.parse(text.get());
                } catch (IllegalArgumentException e) {
                    err = e.getMessage();
                }
            }
            this.filter = f;
            this.filterError = err;
        }

        boolean explicit() {
            return binding.isPresent() && binding.get().component().isPresent();
        }

        String explicitComponent() {
            return binding.get().component().get();
        }

        String explicitPort() {
            return binding.get().port().orElse("");
        }

        boolean required() {
            return !spec.optional();
        }
    }

    private static final class Node {
        final Contract contract;
        final List<In> inputs = new ArrayList<>();
        boolean locallyOk;
        boolean satisfied;

        Node(Contract contract) {
            this.contract = contract;
            for (PortSpec p : contract.ports()) {
                if (p.direction() == PortSpec.Direction.IN) {
                    In in = new In(contract.name(), p);
                    in.owner = this;
                    inputs.add(in);
                }
            }
        }

        String name() {
            return contract.name();
        }
    }

    private final Map<String, Node> nodes = new HashMap<>();
    /** Inputs without a rule, or with a filter that has no equality to index, by port type. */
    private final Map<String, Set<In>> inputsByType = new HashMap<>();
    /** Outputs by port type, then by each {@code lower-case-key=value} attribute of their component. */
    private final Map<String, Map<String, Set<Out>>> outputsByHint = new HashMap<>();
    /** Inputs with an explicit rule, by the provider component they name. */
    private final Map<String, Set<In>> explicitByProvider = new HashMap<>();
    /** Inputs with a filter that requires {@code key=value}, by port type, then by that equality. */
    private final Map<String, Map<String, Set<In>>> filterByHint = new HashMap<>();
    private final Map<String, Set<Out>> outputsByType = new HashMap<>();
    /** provider name -> inputs that have one of its outputs as a candidate. */
    private final Map<String, Set<In>> candidateOf = new HashMap<>();

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
        Change ch = new Change();
        for (String r : removes) {
            ch.prevStatus.putIfAbsent(r, nodes.get(r).satisfied);
            detach(r, ch);
            ch.removed.add(r);
        }
        for (Contract c : puts) {
            Node old = nodes.get(c.name());
            if (old != null) {
                if (old.contract.equals(c)) {
                    continue;
                }
                ch.prevStatus.putIfAbsent(c.name(), old.satisfied);
                detach(c.name(), ch);
                ch.replaced.add(c.name());
                // Start from the old status: if it still holds, nothing downstream is disturbed.
                attach(c, ch).satisfied = old.satisfied;
            } else {
                ch.added.add(c.name());
                attach(c, ch);
            }
        }
        return finish(ch);
    }

    /** Working state of one change. */
    private static final class Change {
        final Map<String, Boolean> prevStatus = new HashMap<>();
        final Set<String> dirty = new LinkedHashSet<>();
        final Set<Wire> wiresAdded = new HashSet<>();
        final Set<Wire> wiresRemoved = new HashSet<>();
        final TreeSet<String> added = new TreeSet<>();
        final TreeSet<String> removed = new TreeSet<>();
        final TreeSet<String> replaced = new TreeSet<>();
        int touched;

        void wireGone(Wire w) {
            if (!wiresAdded.remove(w)) {
                wiresRemoved.add(w);
            }
        }

        void wireNew(Wire w) {
            if (!wiresRemoved.remove(w)) {
                wiresAdded.add(w);
            }
        }
    }

    private void detach(String name, Change ch) {
        Node node = nodes.remove(name);
        for (In in : node.inputs) {
            if (in.home != null) {
                in.home.remove(in);
            }
            for (Out o : in.candidates) {
                Set<In> s = candidateOf.get(o.component());
                if (s != null) {
                    s.remove(in);
                }
            }
            if (in.wire != null) {
                ch.wireGone(in.wire);
            }
        }
        for (PortSpec p : node.contract.outputs()) {
            Out out = new Out(name, p);
            outputsByType.get(p.type()).remove(out);
            Map<String, Set<Out>> byHint = outputsByHint.get(p.type());
            for (Map.Entry<String, String> a : node.contract.attributes().entrySet()) {
                Set<Out> set = byHint.get(hintOf(a));
                if (set == null) {
                    continue; // two keys differing only in case, with the same value
                }
                set.remove(out);
                if (set.isEmpty()) {
                    byHint.remove(hintOf(a));
                }
            }
        }
        Set<In> fed = candidateOf.remove(name);
        if (fed != null) {
            for (In in : fed) {
                if (in.consumer.equals(name)) {
                    continue; // its own self-bound input, already gone with it
                }
                in.candidates.removeIf(o -> o.component().equals(name));
                rewire(in, ch);
                ch.dirty.add(in.consumer);
            }
        }
        ch.dirty.remove(name);
    }

    private Node attach(Contract c, Change ch) {
        Node node = new Node(c);
        nodes.put(c.name(), node);
        for (PortSpec p : c.outputs()) {
            Out out = new Out(c.name(), p);
            outputsByType.computeIfAbsent(p.type(), k -> new HashSet<>()).add(out);
            Map<String, Set<Out>> byHint = outputsByHint.computeIfAbsent(p.type(), k -> new HashMap<>());
            for (Map.Entry<String, String> a : c.attributes().entrySet()) {
                byHint.computeIfAbsent(hintOf(a), k -> new HashSet<>()).add(out);
            }
            // Only the inputs that could accept this output are looked at.
            offer(inputsByType.get(p.type()), c, p, out, ch);
            offer(explicitByProvider.get(c.name()), c, p, out, ch);
            Map<String, Set<In>> hinted = filterByHint.get(p.type());
            if (hinted != null) {
                for (Map.Entry<String, String> a : c.attributes().entrySet()) {
                    offer(hinted.get(hintOf(a)), c, p, out, ch);
                }
            }
        }
        for (In in : node.inputs) {
            index(in);
            if (in.explicit()) {
                Node p = nodes.get(in.explicitComponent());
                if (p != null) {
                    p.contract.port(in.explicitPort()).ifPresent(o -> {
                        if (o.direction() == PortSpec.Direction.OUT && matches(in, p.contract, o)) {
                            addCandidate(in, new Out(p.name(), o));
                        }
                    });
                }
            } else {
                Set<Out> outs;
                if (in.filter != null && in.filter.equalityHint().isPresent()) {
                    Map<String, Set<Out>> byHint = outputsByHint.get(in.spec.type());
                    outs = byHint == null ? null : byHint.get(in.filter.equalityHint().get());
                } else {
                    outs = outputsByType.get(in.spec.type());
                }
                if (outs != null) {
                    for (Out o : outs) {
                        if (!o.component().equals(c.name()) && matches(in, nodes.get(o.component()).contract, o.spec())) {
                            addCandidate(in, o);
                        }
                    }
                }
            }
            rewire(in, ch);
        }
        ch.dirty.add(c.name());
        return node;
    }

    private static String hintOf(Map.Entry<String, String> attribute) {
        return attribute.getKey().toLowerCase(java.util.Locale.ROOT) + "=" + attribute.getValue();
    }

    private void offer(Set<In> ins, Contract c, PortSpec p, Out out, Change ch) {
        if (ins == null) {
            return;
        }
        for (In in : ins) {
            if (matches(in, c, p)) {
                in.candidates.add(out);
                candidateOf.computeIfAbsent(c.name(), k -> new HashSet<>()).add(in);
                rewire(in, ch);
                ch.dirty.add(in.consumer);
            }
        }
    }

    private void index(In in) {
        if (in.filterError != null) {
            in.home = null; // matches nothing; nothing to index
        } else if (in.explicit()) {
            in.home = explicitByProvider.computeIfAbsent(in.explicitComponent(), k -> new HashSet<>());
        } else if (in.filter != null && in.filter.equalityHint().isPresent()) {
            in.home = filterByHint.computeIfAbsent(in.spec.type(), k -> new HashMap<>())
                    .computeIfAbsent(in.filter.equalityHint().get(), k -> new HashSet<>());
        } else {
            in.home = inputsByType.computeIfAbsent(in.spec.type(), k -> new HashSet<>());
        }
        if (in.home != null) {
            in.home.add(in);
        }
    }

    private void addCandidate(In in, Out o) {
        in.candidates.add(o);
        candidateOf.computeIfAbsent(o.component(), k -> new HashSet<>()).add(in);
    }

    private static boolean matches(In in, Contract provider, PortSpec out) {
        PortSpec spec = in.spec;
        if (!spec.type().equals(out.type()) || spec.method() != out.method()
                || !out.typeVersion().canFeed(spec.typeVersion())) {
            return false;
        }
        if (in.explicit()) {
            return provider.name().equals(in.explicitComponent()) && out.name().equals(in.explicitPort());
        }
        if (provider.name().equals(in.consumer)) {
            return false;
        }
        if (in.filterError != null) {
            return false;
        }
        return in.filter == null || in.filter.matches(provider.attributes());
    }

    private void rewire(In in, Change ch) {
        Wire w = null;
        Node pn = null;
        if (in.candidates.size() == 1) {
            Out o = in.candidates.first();
            w = new Wire(in.consumer, in.spec.name(), o.component(), o.spec().name());
            pn = nodes.get(o.component());
        }
        in.providerNode = pn;
        if (w == null ? in.wire != null : !w.equals(in.wire)) {
            if (in.wire != null) {
                ch.wireGone(in.wire);
            }
            if (w != null) {
                ch.wireNew(w);
            }
            in.wire = w;
        }
    }

    private static boolean locallyOk(Node n) {
        for (In in : n.inputs) {
            if (in.required() && in.wire == null) {
                return false;
            }
        }
        return true;
    }

    private boolean eval(Node n, Change ch) {
        ch.touched++;
        if (!n.locallyOk) {
            return false;
        }
        for (In in : n.inputs) {
            if (in.required()) {
                Node p = in.providerNode;
                if (p == null || !p.satisfied) {
                    return false;
                }
            }
        }
        return true;
    }

    /** Consumers whose required input is wired to {@code provider}. */
    private List<Node> requiredDependents(String provider) {
        Set<In> fed = candidateOf.get(provider);
        if (fed == null || fed.isEmpty()) {
            return List.of();
        }
        List<Node> out = new ArrayList<>();
        for (In in : fed) {
            if (in.required() && in.wire != null && in.wire.provider().equals(provider)
                    && nodes.get(in.consumer) == in.owner) {
                out.add(in.owner);
            }
        }
        return out;
    }

    private void setStatus(Node n, boolean sat, Change ch) {
        if (n.satisfied != sat) {
            ch.prevStatus.putIfAbsent(n.name(), n.satisfied);
            n.satisfied = sat;
        }
    }

    /** Bumped by every change; the cycle cache is valid for one version. */
    private long version;
    private long sccVersion = -1;
    private final Map<String, Integer> sccOf = new HashMap<>();
    private final Map<Integer, Integer> sccSize = new HashMap<>();

    private ResolveDelta finish(Change ch) {
        version++;
        // Local status of every dirty node (its wires may have changed).
        List<Node> dirty = new ArrayList<>();
        for (String d : ch.dirty) {
            Node n = nodes.get(d);
            if (n != null) {
                n.locallyOk = locallyOk(n);
                dirty.add(n);
            }
        }
        ch.touched += dirty.size();
        // Down: what can no longer be satisfied, propagated to satisfied dependents. The
        // satisfied set left is a post-fixpoint, hence below the new greatest fixpoint.
        ArrayDeque<Node> work = new ArrayDeque<>(dirty);
        while (!work.isEmpty()) {
            Node n = work.poll();
            if (n.satisfied && !eval(n, ch)) {
                setStatus(n, false, ch);
                for (Node d : requiredDependents(n.name())) {
                    if (d.satisfied) {
                        work.add(d);
                    }
                }
            }
        }
        // Up: the unsatisfied, locally complete region downstream of what changed may come up.
        // Solve the greatest fixpoint inside it, everything outside held fixed.
        Set<Node> region = new LinkedHashSet<>();
        ArrayDeque<Node> grow = new ArrayDeque<>();
        for (Node n : dirty) {
            if (!n.satisfied && n.locallyOk && region.add(n)) {
                grow.add(n);
            }
        }
        // Nodes the down phase lowered need not be seeds: each went down because of a provider
        // that is unsatisfied for good, or that comes up only if reachable from a dirty seed,
        // and then the growth below reaches them too (they are unsatisfied and locally complete).
        while (!grow.isEmpty()) {
            Node n = grow.poll();
            for (Node d : requiredDependents(n.name())) {
                if (!d.satisfied && d.locallyOk && region.add(d)) {
                    grow.add(d);
                }
            }
        }
        for (Node n : region) {
            setStatus(n, true, ch);
        }
        work.addAll(region);
        while (!work.isEmpty()) {
            Node n = work.poll();
            if (n.satisfied && !eval(n, ch)) {
                setStatus(n, false, ch);
                for (Node d : requiredDependents(n.name())) {
                    if (d.satisfied && region.contains(d)) {
                        work.add(d);
                    }
                }
            }
        }
        TreeSet<String> up = new TreeSet<>();
        TreeSet<String> down = new TreeSet<>();
        for (String a : ch.added) {
            Node n = nodes.get(a);
            if (n != null) {
                (n.satisfied ? up : down).add(a);
            }
        }
        for (Map.Entry<String, Boolean> e : ch.prevStatus.entrySet()) {
            Node n = nodes.get(e.getKey());
            if (n == null || ch.added.contains(e.getKey())) {
                continue;
            }
            if (n.satisfied && !e.getValue()) {
                up.add(n.name());
            } else if (!n.satisfied && e.getValue()) {
                down.add(n.name());
            }
        }
        TreeSet<String> rewired = new TreeSet<>();
        for (Wire w : ch.wiresAdded) {
            rewired.add(w.consumer());
        }
        for (Wire w : ch.wiresRemoved) {
            rewired.add(w.consumer());
        }
        rewired.removeAll(ch.added);
        rewired.removeAll(ch.removed);
        return new ResolveDelta(ch.added, ch.removed, ch.replaced, rewired, up, down,
                new ArrayList<>(ch.wiresAdded), new ArrayList<>(ch.wiresRemoved), ch.touched);
    }

    /** The installed contract of that name. */
    public Optional<Contract> contract(String name) {
        Node n = nodes.get(name);
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
        for (Node n : nodes.values()) {
            for (In in : n.inputs) {
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
        for (Node n : nodes.values()) {
            for (In in : n.inputs) {
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
        Node n = nodes.get(consumer);
        if (n == null) {
            return List.of();
        }
        List<Wire> out = new ArrayList<>();
        for (In in : n.inputs) {
            if (in.wire != null) {
                out.add(in.wire);
            }
        }
        Collections.sort(out);
        return Collections.unmodifiableList(out);
    }

    /** The wires out of the outputs of {@code provider}, sorted; empty when not installed. */
    public List<Wire> outputWires(String provider) {
        Set<In> fed = candidateOf.get(provider);
        if (fed == null) {
            return List.of();
        }
        List<Wire> out = new ArrayList<>();
        for (In in : fed) {
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
        Node n = nodes.get(name);
        return n != null && n.satisfied;
    }

    /** Satisfied component names, sorted. */
    public SortedSet<String> satisfied() {
        TreeSet<String> s = new TreeSet<>();
        for (Node n : nodes.values()) {
            if (n.satisfied) {
                s.add(n.name());
            }
        }
        return Collections.unmodifiableSortedSet(s);
    }

    /** True when the input of that component is optional (false when unknown). */
    public boolean isOptionalInput(String consumer, String inPort) {
        Node n = nodes.get(consumer);
        if (n == null) {
            return false;
        }
        for (In in : n.inputs) {
            if (in.spec.name().equals(inPort)) {
                return in.spec.optional();
            }
        }
        return false;
    }

    /** Names of the components {@code name} requires (providers of its wired required inputs). */
    public Set<String> requiredProviders(String name) {
        Node n = nodes.get(name);
        if (n == null) {
            return Set.of();
        }
        TreeSet<String> s = new TreeSet<>();
        for (In in : n.inputs) {
            if (in.required() && in.wire != null) {
                s.add(in.wire.provider());
            }
        }
        return Collections.unmodifiableSet(s);
    }

    /**
     * Satisfaction of one component with its reasons and notes.
     *
     * @throws IllegalArgumentException naming it when it is not installed
     */
    public Satisfaction satisfaction(String name) {
        Node n = nodes.get(name);
        if (n == null) {
            throw new IllegalArgumentException("component '" + name + "' is not installed");
        }
        List<String> reasons = new ArrayList<>();
        List<String> notes = new ArrayList<>();
        for (In in : n.inputs) {
            String head = "input '" + in.spec.name() + "' of '" + name + "': ";
            String problem = null;
            if (in.filterError != null) {
                problem = head + "invalid binding filter: " + in.filterError;
            } else if (in.candidates.isEmpty()) {
                problem = missing(in, head);
            } else if (in.candidates.size() > 1) {
                List<String> refs = new ArrayList<>();
                for (Out o : in.candidates) {
                    refs.add(o.ref());
                }
                problem = head + "ambiguous: " + String.join(", ", refs);
            }
            if (problem != null) {
                if (in.required()) {
                    reasons.add(problem);
                } else {
                    notes.add("optional " + problem + " (not blocking)");
                }
            } else if (in.required()) {
                Node p = nodes.get(in.wire.provider());
                if (!p.satisfied) {
                    reasons.add(head + "provider '" + p.name() + "' is Unsatisfied");
                }
            }
        }
        if (!n.satisfied && reasons.isEmpty()) {
            // Cannot happen with a consistent fixpoint; say so rather than return no reason.
            reasons.add("'" + name + "' is Unsatisfied (inconsistent resolver state)");
        }
        List<String> cycle = cycleThrough(n);
        if (!cycle.isEmpty()) {
            notes.add("in cycle: " + String.join(" -> ", cycle));
        }
        return new Satisfaction(name, n.satisfied, n.satisfied ? List.of() : reasons, notes);
    }

    private String missing(In in, String head) {
        PortSpec s = in.spec;
        String wanted = s.type() + " " + s.typeVersion().major() + "."
                + (s.typeVersion().minor() == 0 ? "x" : s.typeVersion().minor() + "+") + " ("
                + s.method().name().toLowerCase(java.util.Locale.ROOT) + ")";
        if (in.explicit()) {
            String ref = in.explicitComponent() + "." + in.explicitPort();
            Node p = nodes.get(in.explicitComponent());
            if (p == null) {
                return head + "explicit provider '" + ref + "' is not installed";
            }
            Optional<PortSpec> o = p.contract.port(in.explicitPort());
            if (o.isEmpty() || o.get().direction() != PortSpec.Direction.OUT) {
                return head + "'" + p.name() + "' has no output '" + in.explicitPort() + "'";
            }
            return head + ref + " is " + describe(o.get()) + ", needs " + wanted;
        }
        StringBuilder sb = new StringBuilder(head).append("no provider of ").append(wanted);
        in.binding.flatMap(Binding::filter).ifPresent(f -> sb.append(" matching ").append(f));
        // Near misses: same type name, something else differs.
        TreeSet<Out> near = new TreeSet<>();
        Set<Out> outs = outputsByType.get(s.type());
        if (outs != null) {
            for (Out o : outs) {
                if (!o.component().equals(in.consumer)) {
                    near.add(o);
                }
            }
        }
        if (!near.isEmpty()) {
            List<String> list = new ArrayList<>();
            for (Out o : near) {
                if (list.size() == 5) {
                    list.add("...");
                    break;
                }
                boolean typeOk = o.spec().method() == s.method() && o.spec().typeVersion().canFeed(s.typeVersion());
                list.add(o.ref() + " " + (typeOk ? "(filter does not match)" : describe(o.spec())));
            }
            sb.append("; not matching: ").append(String.join(", ", list));
        }
        return sb.toString();
    }

    private static String describe(PortSpec p) {
        return p.type() + " " + p.typeVersion() + " (" + p.method().name().toLowerCase(java.util.Locale.ROOT) + ")";
    }

    /**
     * The shortest cycle of required wires through {@code n} in data-flow order (provider to
     * consumer), starting and ending at n; empty when n is on no cycle.
     */
    private List<String> cycleThrough(Node n) {
        if (sccVersion != version) {
            sccOf.clear();
            sccSize.clear();
            int id = 0;
            for (List<String> comp : Graphs.sccs(nodes.keySet(), this::requiredProviders)) {
                for (String m : comp) {
                    sccOf.put(m, id);
                }
                sccSize.put(id, comp.size());
                id++;
            }
            sccVersion = version;
        }
        int mine = sccOf.get(n.name());
        if (sccSize.get(mine) == 1 && !requiredProviders(n.name()).contains(n.name())) {
            return List.of();
        }
        Map<String, String> parent = new HashMap<>();
        ArrayDeque<String> q = new ArrayDeque<>();
        q.add(n.name());
        parent.put(n.name(), null);
        while (!q.isEmpty()) {
            String cur = q.poll();
            TreeSet<String> next = new TreeSet<>();
            for (Node d : requiredDependents(cur)) {
                next.add(d.name());
            }
            for (String d : next) {
                if (d.equals(n.name())) {
                    List<String> path = new ArrayList<>();
                    for (String x = cur; x != null; x = parent.get(x)) {
                        path.add(0, x);
                    }
                    path.add(n.name());
                    return path;
                }
                if (!parent.containsKey(d) && sccOf.get(d) == mine) {
                    parent.put(d, cur);
                    q.add(d);
                }
            }
        }
        return List.of();
    }

    /**
     * Cycles through wires of required inputs: each strongly connected component of more than
     * one member, or a single member bound to itself, as its names sorted; the list sorted by
     * first name.
     */
    public List<List<String>> cycles() {
        Map<String, Set<String>> edges = new HashMap<>();
        for (Node n : nodes.values()) {
            edges.put(n.name(), requiredProviders(n.name()));
        }
        return Graphs.cycles(edges);
    }
}
