package org.arflex.planner.impl;

import java.util.ArrayDeque;
import java.util.ArrayList;
import java.util.HashMap;
import java.util.List;
import java.util.Map;
import java.util.Optional;
import java.util.Set;
import java.util.TreeSet;
import org.arflex.contract.Binding;
import org.arflex.contract.PortSpec;
import org.arflex.planner.Satisfaction;

/**
 * Explains the {@link Resolver}'s status of one component: the reason of each input that blocks
 * it (missing provider with near misses, ambiguity, bad filter, unsatisfied provider), notes on
 * optional inputs and the shortest cycle of required wires through it (strongly connected
 * components cached per change).
 */
final class SatisfactionReport {
    private final Map<String, ResolverNode> nodes;
    private final ResolverIndex index;

    SatisfactionReport(ResolverIndex index) {
        this.index = index;
        this.nodes = index.nodes;
    }

    /** Called at every change: the cycle cache is stale. */
    void changed() {
        version++;
    }

    /** Bumped by every change; the cycle cache is valid for one version. */
    private long version;
    private long sccVersion = -1;
    private final Map<String, Integer> sccOf = new HashMap<>();
    private final Map<Integer, Integer> sccSize = new HashMap<>();

    /**
     * Satisfaction of one component with its reasons and notes.
     *
     * @throws IllegalArgumentException naming it when it is not installed
     */
    Satisfaction satisfaction(String name) {
        ResolverNode n = nodes.get(name);
        if (n == null) {
            throw new IllegalArgumentException("component '" + name + "' is not installed");
        }
        List<String> reasons = new ArrayList<>();
        List<String> notes = new ArrayList<>();
        for (ResolverIn in : n.inputs) {
            String head = "input '" + in.spec.name() + "' of '" + name + "': ";
            String problem = null;
            if (in.filterError != null) {
                problem = head + "invalid binding filter: " + in.filterError;
            } else if (in.candidates.isEmpty()) {
                problem = missing(in, head);
            } else if (in.candidates.size() > 1) {
                List<String> refs = new ArrayList<>();
                for (ResolverOut o : in.candidates) {
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
                ResolverNode p = nodes.get(in.wire.provider());
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

    private String missing(ResolverIn in, String head) {
        PortSpec s = in.spec;
        String wanted = s.type() + " " + s.typeVersion().major() + "."
                + (s.typeVersion().minor() == 0 ? "x" : s.typeVersion().minor() + "+") + " ("
                + s.method().name().toLowerCase(java.util.Locale.ROOT) + ")";
        if (in.explicit()) {
            String ref = in.explicitComponent() + "." + in.explicitPort();
            ResolverNode p = nodes.get(in.explicitComponent());
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
        TreeSet<ResolverOut> near = new TreeSet<>();
        Set<ResolverOut> outs = index.outputsOfType(s.type());
        if (outs != null) {
            for (ResolverOut o : outs) {
                if (!o.component().equals(in.consumer)) {
                    near.add(o);
                }
            }
        }
        if (!near.isEmpty()) {
            List<String> list = new ArrayList<>();
            for (ResolverOut o : near) {
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
    private List<String> cycleThrough(ResolverNode n) {
        if (sccVersion != version) {
            sccOf.clear();
            sccSize.clear();
            int id = 0;
            for (List<String> comp : Graphs.sccs(nodes.keySet(), index::requiredProviders)) {
                for (String m : comp) {
                    sccOf.put(m, id);
                }
                sccSize.put(id, comp.size());
                id++;
            }
            sccVersion = version;
        }
        int mine = sccOf.get(n.name());
        if (sccSize.get(mine) == 1 && !index.requiredProviders(n.name()).contains(n.name())) {
            return List.of();
        }
        Map<String, String> parent = new HashMap<>();
        ArrayDeque<String> q = new ArrayDeque<>();
        q.add(n.name());
        parent.put(n.name(), null);
        while (!q.isEmpty()) {
            String cur = q.poll();
            TreeSet<String> next = new TreeSet<>();
            for (ResolverNode d : index.requiredDependents(cur)) {
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
}
