package org.arflex.drcr.impl.lifecycle;

import java.util.Collections;
import java.util.EnumMap;
import java.util.EnumSet;
import java.util.Map;
import java.util.Set;

/**
 * The one transition table of the lifecycle. Everything that changes a state asks this table;
 * nothing else encodes which transition is legal.
 */
public final class Transitions {

    private static final Map<State, Set<State>> TABLE;

    static {
        EnumMap<State, Set<State>> t = new EnumMap<>(State.class);
        // Installed -> Unsatisfied once the contract is registered with the resolver.
        t.put(State.INSTALLED, Collections.unmodifiableSet(EnumSet.of(State.UNSATISFIED, State.DESTROYED)));
        // Unsatisfied -> Active is automatic when inputs, resources and reset are all there;
        // Unsatisfied -> Failed when the RT half cannot even start and restarts are exhausted.
        t.put(State.UNSATISFIED, Collections.unmodifiableSet(
                EnumSet.of(State.ACTIVE, State.DESTROYED, State.FAILED)));
        // Active -> Unsatisfied when an input, a resource or the RT half goes away.
        t.put(State.ACTIVE, Collections.unmodifiableSet(
                EnumSet.of(State.UNSATISFIED, State.DESTROYED, State.FAILED)));
        // Failed leaves only by an operator reset, an update, or removal.
        t.put(State.FAILED, Collections.unmodifiableSet(EnumSet.of(State.UNSATISFIED, State.DESTROYED)));
        // Destroyed is terminal: a reinstalled bundle makes a new instance.
        t.put(State.DESTROYED, Collections.unmodifiableSet(EnumSet.noneOf(State.class)));
        TABLE = Collections.unmodifiableMap(t);
    }

    private Transitions() {
    }

    /** True when {@code from -> to} is in the table. */
    public static boolean allowed(State from, State to) {
        return TABLE.get(from).contains(to);
    }

    /** The states reachable from {@code from} in one step. */
    public static Set<State> from(State from) {
        return TABLE.get(from);
    }
}
