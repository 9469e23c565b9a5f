package org.arflex.planner;

import java.util.ArrayList;
import java.util.Collections;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import java.util.Objects;
import java.util.Optional;
import java.util.SortedMap;
import java.util.SortedSet;
import java.util.TreeMap;
import java.util.TreeSet;
import org.arflex.contract.Contract;
import org.arflex.planner.impl.Text;

/**
 * A proposed change of the cell, immutable. Build one with the static factories or
 * {@link #builder()}; a change may combine several parts, which {@link Planner} applies
 * together as one step.
 *
 * <p>Parts: install new contracts, replace installed ones (a bundle update), uninstall, put
 * (install or replace, whichever applies), a new set of capacities, measured WCETs from the
 * Resource Manager (0 clears a measurement), and blocking: a blocked component is kept
 * installed but not started (for example Failed after its restarts ran out, or stopped by the
 * operator), which takes its dependents down as a missing provider would; unblocking lets it
 * start again.
 */
public final class Change {

    private static final Change NONE = new Builder().build();

    private final List<Contract> installs;
    private final List<Contract> replaces;
    private final List<Contract> puts;
    private final SortedSet<String> uninstalls;
    private final Optional<Capacities> capacities;
    private final SortedMap<String, Long> measuredWcetNs;
    private final SortedMap<String, String> blocks;
    private final SortedSet<String> unblocks;
    private final SortedMap<String, Overlap> overlaps;
    private final Optional<String> cause;

    /**
     * An update whose old and new RT halves run side by side for a while (docs/DECISIONS.md D51):
     * a change set's update runs its new half in a shadow run before the switch (D42) and keeps
     * the old half running for a rollback window after it (D38). The plan then counts both halves
     * on their CPUs in each phase ({@link Plan#transients()}).
     *
     * @param component    the replaced component
     * @param shadowCycles cycles of the shadow run, 0 for none
     * @param windowCycles cycles of the rollback window, 0 for none
     */
    public record Overlap(String component, long shadowCycles, long windowCycles) {

        /** @throws IllegalArgumentException naming the component when a number of cycles is negative */
        public Overlap {
            Objects.requireNonNull(component, "component");
            if (shadowCycles < 0 || windowCycles < 0) {
                throw new IllegalArgumentException("overlap '" + component + "': cycles must not be negative (shadow "
                        + shadowCycles + ", window " + windowCycles + ")");
            }
        }
    }

    private Change(Builder b) {
        installs = List.copyOf(b.installs);
        replaces = List.copyOf(b.replaces);
        puts = List.copyOf(b.puts);
        uninstalls = Collections.unmodifiableSortedSet(new TreeSet<>(b.uninstalls));
        capacities = b.capacities;
        measuredWcetNs = Collections.unmodifiableSortedMap(new TreeMap<>(b.measuredWcetNs));
        blocks = Collections.unmodifiableSortedMap(new TreeMap<>(b.blocks));
        unblocks = Collections.unmodifiableSortedSet(new TreeSet<>(b.unblocks));
        overlaps = Collections.unmodifiableSortedMap(new TreeMap<>(b.overlaps));
        cause = b.cause;
    }

    /** The empty change: planning it reconciles the Active set with what should run. */
    public static Change none() {
        return NONE;
    }

    /** Install new contracts (their names must not be installed yet). */
    public static Change install(Contract... contracts) {
        Builder b = builder();
        for (Contract c : contracts) {
            b.install(c);
        }
        return b.build();
    }

    /** Replace installed contracts by new versions (a bundle update). */
    public static Change replace(Contract... contracts) {
        Builder b = builder();
        for (Contract c : contracts) {
            b.replace(c);
        }
        return b.build();
    }

    /** Install or replace, whichever applies to each name. */
    public static Change put(Contract... contracts) {
        Builder b = builder();
        for (Contract c : contracts) {
            b.put(c);
        }
        return b.build();
    }

    /** Uninstall components by name. */
    public static Change uninstall(String... names) {
        Builder b = builder();
        for (String n : names) {
            b.uninstall(n);
        }
        return b.build();
    }

    /** New capacities from the Resource Manager. */
    public static Change capacities(Capacities capacities) {
        return builder().capacities(capacities).build();
    }

    /**
     * New capacities with what caused them (for example {@code cpu 1 left the runtime's cpuset
     * /x (cgroup v1)}): the plan's title and the reasons of the components it stops, moves or
     * starts name it.
     */
    public static Change capacities(Capacities capacities, String cause) {
        return builder().capacities(capacities).cause(cause).build();
    }

    /** A measured WCET of one component (0 clears it). */
    public static Change measuredWcet(String name, long wcetNs) {
        return builder().measuredWcet(name, wcetNs).build();
    }

    /** Block a component with a reason (it stays installed but is not started). */
    public static Change block(String name, String reason) {
        return builder().block(name, reason).build();
    }

    /** Unblock a component. */
    public static Change unblock(String name) {
        return builder().unblock(name).build();
    }

    /** A builder for a change with several parts. */
    public static Builder builder() {
        return new Builder();
    }

    /** Contracts to install, in the order given. */
    public List<Contract> installs() {
        return installs;
    }

    /** Contracts that replace installed ones, in the order given. */
    public List<Contract> replaces() {
        return replaces;
    }

    /** Contracts to install or replace, in the order given. */
    public List<Contract> puts() {
        return puts;
    }

    /** Names to uninstall. */
    public SortedSet<String> uninstalls() {
        return uninstalls;
    }

    /** New capacities, if this change carries them. */
    public Optional<Capacities> capacities() {
        return capacities;
    }

    /** Measured WCETs to record, ns; 0 clears a measurement. */
    public SortedMap<String, Long> measuredWcetNs() {
        return measuredWcetNs;
    }

    /** Components to block, with the reason shown for them. */
    public SortedMap<String, String> blocks() {
        return blocks;
    }

    /** Components to unblock. */
    public SortedSet<String> unblocks() {
        return unblocks;
    }

    /**
     * Replaced components whose old and new halves run side by side for a while, by name (a
     * change set's update: D51). Empty for every other change.
     */
    public SortedMap<String, Overlap> overlaps() {
        return overlaps;
    }

    /**
     * What caused this change, when it was not asked for through an API: for example the machine
     * took a CPU away. The plan appends it to its title and to the reasons of its actions.
     */
    public Optional<String> cause() {
        return cause;
    }

    /** True when the change has no part at all. */
    public boolean isEmpty() {
        return installs.isEmpty() && replaces.isEmpty() && puts.isEmpty() && uninstalls.isEmpty()
                && capacities.isEmpty() && measuredWcetNs.isEmpty() && blocks.isEmpty() && unblocks.isEmpty()
                && overlaps.isEmpty();
    }

    /**
     * A one-line description, for example {@code install a 1.0.0, b 1.0.0; uninstall c}. The
     * planner's {@link Plan#title()} is more precise (it knows the replaced versions).
     */
    public String describe() {
        List<String> parts = new ArrayList<>();
        if (!installs.isEmpty()) {
            parts.add("install " + names(installs));
        }
        if (!replaces.isEmpty()) {
            parts.add("replace " + names(replaces));
        }
        if (!puts.isEmpty()) {
            parts.add("put " + names(puts));
        }
        if (!uninstalls.isEmpty()) {
            parts.add("uninstall " + String.join(", ", uninstalls));
        }
        capacities.ifPresent(c -> parts.add("capacities " + Text.capacities(c)));
        if (!measuredWcetNs.isEmpty()) {
            List<String> m = new ArrayList<>();
            measuredWcetNs.forEach((n, w) -> m.add(n + "=" + (w == 0 ? "cleared" : Text.duration(w))));
            parts.add("measured WCET " + String.join(", ", m));
        }
        if (!blocks.isEmpty()) {
            parts.add("block " + String.join(", ", blocks.keySet()));
        }
        if (!unblocks.isEmpty()) {
            parts.add("unblock " + String.join(", ", unblocks));
        }
        if (!overlaps.isEmpty()) {
            List<String> o = new ArrayList<>();
            overlaps.values().forEach(v -> o.add(v.component() + " (shadow " + v.shadowCycles() + ", window "
                    + v.windowCycles() + " cycles)"));
            parts.add("both halves " + String.join(", ", o));
        }
        return parts.isEmpty() ? "no change" : String.join("; ", parts);
    }

    private static String names(List<Contract> cs) {
        List<String> s = new ArrayList<>();
        for (Contract c : cs) {
            s.add(c.name() + " " + c.version());
        }
        return String.join(", ", s);
    }

    @Override
    public String toString() {
        return describe();
    }

    /** Collects the parts of a change. Not thread-safe. */
    public static final class Builder {
        private final List<Contract> installs = new ArrayList<>();
        private final List<Contract> replaces = new ArrayList<>();
        private final List<Contract> puts = new ArrayList<>();
        private final List<String> uninstalls = new ArrayList<>();
        private Optional<Capacities> capacities = Optional.empty();
        private final Map<String, Long> measuredWcetNs = new LinkedHashMap<>();
        private final Map<String, String> blocks = new LinkedHashMap<>();
        private final List<String> unblocks = new ArrayList<>();
        private final Map<String, Overlap> overlaps = new LinkedHashMap<>();
        private Optional<String> cause = Optional.empty();

        private Builder() {
        }

        /** Adds a contract to install. */
        public Builder install(Contract c) {
            installs.add(Objects.requireNonNull(c, "contract"));
            return this;
        }

        /** Adds a contract that replaces the installed one of the same name. */
        public Builder replace(Contract c) {
            replaces.add(Objects.requireNonNull(c, "contract"));
            return this;
        }

        /** Adds a contract to install or replace. */
        public Builder put(Contract c) {
            puts.add(Objects.requireNonNull(c, "contract"));
            return this;
        }

        /** Adds a component to uninstall. */
        public Builder uninstall(String name) {
            uninstalls.add(Objects.requireNonNull(name, "name"));
            return this;
        }

        /** Sets new capacities. */
        public Builder capacities(Capacities c) {
            capacities = Optional.of(Objects.requireNonNull(c, "capacities"));
            return this;
        }

        /** Records a measured WCET in ns (0 clears it). */
        public Builder measuredWcet(String name, long wcetNs) {
            if (wcetNs < 0) {
                throw new IllegalArgumentException("measured WCET of '" + name + "' is negative: " + wcetNs + " ns");
            }
            measuredWcetNs.put(Objects.requireNonNull(name, "name"), wcetNs);
            return this;
        }

        /** Blocks a component with a reason. */
        public Builder block(String name, String reason) {
            blocks.put(Objects.requireNonNull(name, "name"), Objects.requireNonNull(reason, "reason"));
            return this;
        }

        /** Unblocks a component. */
        public Builder unblock(String name) {
            unblocks.add(Objects.requireNonNull(name, "name"));
            return this;
        }

        /**
         * Says that the old and the new half of a component this change replaces run side by
         * side: {@code shadowCycles} of the new one's shadow run before the switch, then
         * {@code windowCycles} of the old one's rollback window after it (0: none). The plan
         * counts both halves in each phase ({@link Plan#transients()}).
         *
         * @throws IllegalArgumentException naming the component when a number is negative
         */
        public Builder overlap(String component, long shadowCycles, long windowCycles) {
            overlaps.put(Objects.requireNonNull(component, "component"),
                    new Overlap(component, shadowCycles, windowCycles));
            return this;
        }

        /**
         * Says what caused the change (see {@link Change#cause()}).
         *
         * @throws IllegalArgumentException when the cause is blank
         */
        public Builder cause(String why) {
            if (Objects.requireNonNull(why, "cause").isBlank()) {
                throw new IllegalArgumentException("the cause of a change must not be blank");
            }
            cause = Optional.of(why.strip());
            return this;
        }

        /** The immutable change. */
        public Change build() {
            return new Change(this);
        }
    }
}
