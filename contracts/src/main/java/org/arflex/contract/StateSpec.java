package org.arflex.contract;

import java.util.List;

/**
 * The state block a component hands to its next version at a change set's switch (SPEC §12.1,
 * docs/DECISIONS.md D41): a value of port type {@code type}, which its RT half publishes every
 * cycle and a new version adopts once before its first cycle.
 *
 * @param type         port type name of the state block (a known type that allows {@code state})
 * @param typeVersion  the version of that type the component is built against
 * @param convertsFrom older state blocks this version converts when it adopts one, in document order
 */
public record StateSpec(String type, TypeVersion typeVersion, List<From> convertsFrom) {

    public StateSpec {
        convertsFrom = List.copyOf(convertsFrom);
    }

    /** A state block of another type or version that this version declares it converts. */
    public record From(String type, TypeVersion typeVersion) {
        @Override
        public String toString() {
            return type + " " + typeVersion;
        }
    }

    /**
     * True when this version adopts the state block {@code type} {@code version} a running
     * version publishes: the same type whose version can feed this one (SPEC §13.4), or one it
     * declares it converts (same type, a version that can feed the declared one).
     */
    public boolean adopts(String otherType, TypeVersion version) {
        if (type.equals(otherType) && version.canFeed(typeVersion)) {
            return true;
        }
        return convertsFrom.stream().anyMatch(f -> f.type().equals(otherType) && version.canFeed(f.typeVersion()));
    }

    @Override
    public String toString() {
        return type + " " + typeVersion;
    }
}
