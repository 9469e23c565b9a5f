package org.arflex.planner.impl;

import java.util.ArrayList;
import java.util.Collections;
import java.util.HashMap;
import java.util.HashSet;
import java.util.List;
import java.util.Map;
import java.util.Set;
import java.util.TreeSet;
import org.arflex.contract.Contract;
import org.arflex.contract.PortSpec;
import org.arflex.planner.Wire;

/**
 * The matching half of the {@link Resolver}: the installed components, the indexes of outputs and
 * inputs (by port type, attribute equality, explicit provider) and which inputs each provider is a
 * candidate for; attaches and detaches components, offering each new output only to the inputs
 * that could accept it, and rewires the inputs whose candidates changed.
 */
final class ResolverIndex {
    /** The installed components by name (shared with the resolver's other parts). */
    final Map<String, ResolverNode> nodes = new HashMap<>();
    /** Inputs without a rule, or with a filter that has no equality to index, by port type. */
    private final Map<String, Set<ResolverIn>> inputsByType = new HashMap<>();
    /** Outputs by port type, then by each {@code lower-case-key=value} attribute of their component. */
    private final Map<String, Map<String, Set<ResolverOut>>> outputsByHint = new HashMap<>();
    /** Inputs with an explicit rule, by the provider component they name. */
    private final Map<String, Set<ResolverIn>> explicitByProvider = new HashMap<>();
    /** Inputs with a filter that requires {@code key=value}, by port type, then by that equality. */
    private final Map<String, Map<String, Set<ResolverIn>>> filterByHint = new HashMap<>();
    private final Map<String, Set<ResolverOut>> outputsByType = new HashMap<>();
    /** provider name -> inputs that have one of its outputs as a candidate. */
    private final Map<String, Set<ResolverIn>> candidateOf = new HashMap<>();

    void detach(String name, ResolverChange ch) {
        ResolverNode node = nodes.remove(name);
        for (ResolverIn in : node.inputs) {
            if (in.home != null) {
                in.home.remove(in);
            }
            for (ResolverOut o : in.candidates) {
                Set<ResolverIn> s = candidateOf.get(o.component());
                if (s != null) {
                    s.remove(in);
                }
            }
            if (in.wire != null) {
                ch.wireGone(in.wire);
            }
        }
        for (PortSpec p : node.contract.outputs()) {
            ResolverOut out = new ResolverOut(name, p);
            outputsByType.get(p.type()).remove(out);
            Map<String, Set<ResolverOut>> byHint = outputsByHint.get(p.type());
            for (Map.Entry<String, String> a : node.contract.attributes().entrySet()) {
                Set<ResolverOut> set = byHint.get(hintOf(a));
                if (set == null) {
                    continue; // two keys differing only in case, with the same value
                }
                set.remove(out);
                if (set.isEmpty()) {
                    byHint.remove(hintOf(a));
                }
            }
        }
        Set<ResolverIn> fed = candidateOf.remove(name);
        if (fed != null) {
            for (ResolverIn in : fed) {
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

    ResolverNode attach(Contract c, ResolverChange ch) {
        ResolverNode node = new ResolverNode(c);
        nodes.put(c.name(), node);
        for (PortSpec p : c.outputs()) {
            ResolverOut out = new ResolverOut(c.name(), p);
            outputsByType.computeIfAbsent(p.type(), k -> new HashSet<>()).add(out);
            Map<String, Set<ResolverOut>> byHint = outputsByHint.computeIfAbsent(p.type(), k -> new HashMap<>());
            for (Map.Entry<String, String> a : c.attributes().entrySet()) {
                byHint.computeIfAbsent(hintOf(a), k -> new HashSet<>()).add(out);
            }
            // Only the inputs that could accept this output are looked at.
            offer(inputsByType.get(p.type()), c, p, out, ch);
            offer(explicitByProvider.get(c.name()), c, p, out, ch);
            Map<String, Set<ResolverIn>> hinted = filterByHint.get(p.type());
            if (hinted != null) {
                for (Map.Entry<String, String> a : c.attributes().entrySet()) {
                    offer(hinted.get(hintOf(a)), c, p, out, ch);
                }
            }
        }
        for (ResolverIn in : node.inputs) {
            index(in);
            if (in.explicit()) {
                ResolverNode p = nodes.get(in.explicitComponent());
                if (p != null) {
                    p.contract.port(in.explicitPort()).ifPresent(o -> {
                        if (o.direction() == PortSpec.Direction.OUT && matches(in, p.contract, o)) {
                            addCandidate(in, new ResolverOut(p.name(), o));
                        }
                    });
                }
            } else {
                Set<ResolverOut> outs;
                if (in.filter != null && in.filter.equalityHint().isPresent()) {
                    Map<String, Set<ResolverOut>> byHint = outputsByHint.get(in.spec.type());
                    outs = byHint == null ? null : byHint.get(in.filter.equalityHint().get());
                } else {
                    outs = outputsByType.get(in.spec.type());
                }
                if (outs != null) {
                    for (ResolverOut o : outs) {
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

    private void offer(Set<ResolverIn> ins, Contract c, PortSpec p, ResolverOut out, ResolverChange ch) {
        if (ins == null) {
            return;
        }
        for (ResolverIn in : ins) {
            if (matches(in, c, p)) {
                in.candidates.add(out);
                candidateOf.computeIfAbsent(c.name(), k -> new HashSet<>()).add(in);
                rewire(in, ch);
                ch.dirty.add(in.consumer);
            }
        }
    }

    private void index(ResolverIn in) {
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

    private void addCandidate(ResolverIn in, ResolverOut o) {
        in.candidates.add(o);
        candidateOf.computeIfAbsent(o.component(), k -> new HashSet<>()).add(in);
    }

    private static boolean matches(ResolverIn in, Contract provider, PortSpec out) {
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

    void rewire(ResolverIn in, ResolverChange ch) {
        Wire w = null;
        ResolverNode pn = null;
        if (in.candidates.size() == 1) {
            ResolverOut o = in.candidates.first();
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

    /** Consumers whose required input is wired to {@code provider}. */
    List<ResolverNode> requiredDependents(String provider) {
        Set<ResolverIn> fed = candidateOf.get(provider);
        if (fed == null || fed.isEmpty()) {
            return List.of();
        }
        List<ResolverNode> out = new ArrayList<>();
        for (ResolverIn in : fed) {
            if (in.required() && in.wire != null && in.wire.provider().equals(provider)
                    && nodes.get(in.consumer) == in.owner) {
                out.add(in.owner);
            }
        }
        return out;
    }

    /** Names of the components {@code name} requires (providers of its wired required inputs). */
    Set<String> requiredProviders(String name) {
        ResolverNode n = nodes.get(name);
        if (n == null) {
            return Set.of();
        }
        TreeSet<String> s = new TreeSet<>();
        for (ResolverIn in : n.inputs) {
            if (in.required() && in.wire != null) {
                s.add(in.wire.provider());
            }
        }
        return Collections.unmodifiableSet(s);
    }

    /** The inputs that have one of {@code provider}'s outputs as a candidate; null when none were ever. */
    Set<ResolverIn> fedBy(String provider) {
        return candidateOf.get(provider);
    }

    /** The outputs of that port type; null when none were ever installed. */
    Set<ResolverOut> outputsOfType(String type) {
        return outputsByType.get(type);
    }
}
