package org.arflex.planner.impl;

import java.util.Collections;
import java.util.List;
import java.util.SortedSet;
import java.util.TreeSet;
import org.arflex.planner.Wire;

/**
 * What one resolver change did. All sets are sorted and unmodifiable.
 *
 * @param added             components that were not installed before
 * @param removed           components that are no longer installed
 * @param replaced          components whose contract was replaced by a different one
 * @param rewired           components (still installed) whose set of input wires changed
 * @param becameSatisfied   components that are satisfied now and were not (or were absent)
 * @param becameUnsatisfied components that are installed, unsatisfied now and were satisfied
 *                          (or were absent)
 * @param wiresAdded        wires that exist now and did not
 * @param wiresRemoved      wires that existed and no longer do
 * @param touched           how many components the change had to re-examine (a measure of
 *                          incrementality: a change far from everything touches only itself)
 */
public record ResolveDelta(
        SortedSet<String> added,
        SortedSet<String> removed,
        SortedSet<String> replaced,
        SortedSet<String> rewired,
        SortedSet<String> becameSatisfied,
        SortedSet<String> becameUnsatisfied,
        List<Wire> wiresAdded,
        List<Wire> wiresRemoved,
        int touched) {

    public ResolveDelta {
        added = freeze(added);
        removed = freeze(removed);
        replaced = freeze(replaced);
        rewired = freeze(rewired);
        becameSatisfied = freeze(becameSatisfied);
        becameUnsatisfied = freeze(becameUnsatisfied);
        wiresAdded = List.copyOf(new TreeSet<>(wiresAdded));
        wiresRemoved = List.copyOf(new TreeSet<>(wiresRemoved));
    }

    private static SortedSet<String> freeze(SortedSet<String> s) {
        return Collections.unmodifiableSortedSet(new TreeSet<>(s));
    }

    /** Every component named in this delta, sorted. */
    public SortedSet<String> changed() {
        TreeSet<String> all = new TreeSet<>();
        all.addAll(added);
        all.addAll(removed);
        all.addAll(replaced);
        all.addAll(rewired);
        all.addAll(becameSatisfied);
        all.addAll(becameUnsatisfied);
        return Collections.unmodifiableSortedSet(all);
    }

    /** True when nothing changed. */
    public boolean isEmpty() {
        return changed().isEmpty() && wiresAdded.isEmpty() && wiresRemoved.isEmpty();
    }
}
