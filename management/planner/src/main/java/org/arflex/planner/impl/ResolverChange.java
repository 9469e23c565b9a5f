package org.arflex.planner.impl;

import java.util.HashMap;
import java.util.HashSet;
import java.util.LinkedHashSet;
import java.util.Map;
import java.util.Set;
import java.util.TreeSet;
import org.arflex.planner.Wire;

/** Working state of one change of the {@link Resolver}: statuses before, dirty names, wires, names changed. */
final class ResolverChange {
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
