package org.arflex.planner.impl;

import java.util.ArrayDeque;
import java.util.ArrayList;
import java.util.LinkedHashSet;
import java.util.List;
import java.util.Map;
import java.util.Set;
import java.util.TreeSet;
import org.arflex.planner.Wire;

/**
 * The satisfaction half of the {@link Resolver}: after a change, lowers what can no longer be
 * satisfied (propagated to satisfied dependents), then solves the greatest fixpoint over the
 * unsatisfied, locally complete region downstream of what changed, and reports the delta.
 */
final class SatisfactionFixpoint {
    private final Map<String, ResolverNode> nodes;
    private final ResolverIndex index;

    SatisfactionFixpoint(ResolverIndex index) {
        this.index = index;
        this.nodes = index.nodes;
    }

    private static boolean locallyOk(ResolverNode n) {
        for (ResolverIn in : n.inputs) {
            if (in.required() && in.wire == null) {
                return false;
            }
        }
        return true;
    }

    private boolean eval(ResolverNode n, ResolverChange ch) {
        ch.touched++;
        if (!n.locallyOk) {
            return false;
        }
        for (ResolverIn in : n.inputs) {
            if (in.required()) {
                ResolverNode p = in.providerNode;
                if (p == null || !p.satisfied) {
                    return false;
                }
            }
        }
        return true;
    }

    private void setStatus(ResolverNode n, boolean sat, ResolverChange ch) {
        if (n.satisfied != sat) {
            ch.prevStatus.putIfAbsent(n.name(), n.satisfied);
            n.satisfied = sat;
        }
    }

    ResolveDelta finish(ResolverChange ch) {
        // Local status of every dirty node (its wires may have changed).
        List<ResolverNode> dirty = new ArrayList<>();
        for (String d : ch.dirty) {
            ResolverNode n = nodes.get(d);
            if (n != null) {
                n.locallyOk = locallyOk(n);
                dirty.add(n);
            }
        }
        ch.touched += dirty.size();
        // Down: what can no longer be satisfied, propagated to satisfied dependents. The
        // satisfied set left is a post-fixpoint, hence below the new greatest fixpoint.
        ArrayDeque<ResolverNode> work = new ArrayDeque<>(dirty);
        while (!work.isEmpty()) {
            ResolverNode n = work.poll();
            if (n.satisfied && !eval(n, ch)) {
                setStatus(n, false, ch);
                for (ResolverNode d : index.requiredDependents(n.name())) {
                    if (d.satisfied) {
                        work.add(d);
                    }
                }
            }
        }
        // Up: the unsatisfied, locally complete region downstream of what changed may come up.
        // Solve the greatest fixpoint inside it, everything outside held fixed.
        Set<ResolverNode> region = new LinkedHashSet<>();
        ArrayDeque<ResolverNode> grow = new ArrayDeque<>();
        for (ResolverNode n : dirty) {
            if (!n.satisfied && n.locallyOk && region.add(n)) {
                grow.add(n);
            }
        }
        // Nodes the down phase lowered need not be seeds: each went down because of a provider
        // that is unsatisfied for good, or that comes up only if reachable from a dirty seed,
        // and then the growth below reaches them too (they are unsatisfied and locally complete).
        while (!grow.isEmpty()) {
            ResolverNode n = grow.poll();
            for (ResolverNode d : index.requiredDependents(n.name())) {
                if (!d.satisfied && d.locallyOk && region.add(d)) {
                    grow.add(d);
                }
            }
        }
        for (ResolverNode n : region) {
            setStatus(n, true, ch);
        }
        work.addAll(region);
        while (!work.isEmpty()) {
            ResolverNode n = work.poll();
            if (n.satisfied && !eval(n, ch)) {
                setStatus(n, false, ch);
                for (ResolverNode d : index.requiredDependents(n.name())) {
                    if (d.satisfied && region.contains(d)) {
                        work.add(d);
                    }
                }
            }
        }
        TreeSet<String> up = new TreeSet<>();
        TreeSet<String> down = new TreeSet<>();
        for (String a : ch.added) {
            ResolverNode n = nodes.get(a);
            if (n != null) {
                (n.satisfied ? up : down).add(a);
            }
        }
        for (Map.Entry<String, Boolean> e : ch.prevStatus.entrySet()) {
            ResolverNode n = nodes.get(e.getKey());
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
}
