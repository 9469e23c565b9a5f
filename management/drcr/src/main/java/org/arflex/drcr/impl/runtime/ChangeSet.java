package org.arflex.drcr.impl.runtime;

import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.Objects;

/**
 * Several actions on the cell planned, admitted and applied together (docs/DECISIONS.md D35):
 * installs of components that are known to the cell but not running (their bundle is installed,
 * not started), uninstalls of running ones, updates of running ones to a new version (D38), and
 * parameter writes. Rewiring follows from the plan.
 * Immutable; build one with {@link #builder()}.
 */
public final class ChangeSet {

    /** One action of a change set. */
    public sealed interface Step {
        /** The component it acts on. */
        String component();

        /** The action as it is written, e.g. {@code install teach}. */
        String text();
    }

    /** Starts a component the cell knows as INSTALLED, running the executable {@code exe}. */
    public record Install(String component, Path exe) implements Step {
        public Install {
            Objects.requireNonNull(component, "component");
            Objects.requireNonNull(exe, "exe");
        }

        @Override
        public String text() {
            return "install " + component;
        }
    }

    /**
     * Replaces the running RT half of {@code component} by a new version (D38): the contract
     * {@code contract} (same name) with the executable {@code exe}, both from {@code from}, already
     * through the code gate. The new half is prepared beside the old one under a generation's
     * object id, switched in the set's actor turn, and the old one is kept warm for
     * {@code window} cycles of the new one (0: stopped at once); a crash or an overrun of the new
     * one within the window rolls the component back to the old half. With {@code shadow > 0} the
     * new half first runs {@code shadow} cycles on the same inputs with its outputs not applied,
     * compared by {@code tolerances} (D42, {@link ShadowRun}); failing, the set is not switched.
     */
    public record Update(String component, org.arflex.contract.Contract contract, Path exe, String from, long window,
                         List<Envelope> envelopes, long shadow, List<Tolerance> tolerances) implements Step {

        public Update(String component, org.arflex.contract.Contract contract, Path exe, String from, long window) {
            this(component, contract, exe, from, window, List.of());
        }

        public Update(String component, org.arflex.contract.Contract contract, Path exe, String from, long window,
                      List<Envelope> envelopes) {
            this(component, contract, exe, from, window, envelopes, 0, List.of());
        }

        public Update {
            envelopes = List.copyOf(envelopes);
            tolerances = List.copyOf(tolerances);
            if (shadow < 0) {
                throw new IllegalArgumentException("shadow " + shadow + " < 0");
            }
            Objects.requireNonNull(component, "component");
            Objects.requireNonNull(contract, "contract");
            Objects.requireNonNull(exe, "exe");
            Objects.requireNonNull(from, "from");
            if (window < 0) {
                throw new IllegalArgumentException("window " + window + " < 0");
            }
        }

        @Override
        public String text() {
            return "update " + component + " " + from;
        }
    }

    /**
     * A range every element of numeric field {@code field} of output {@code port} of an update's
     * new version must stay in during its rollback window (D38); else it is rolled back.
     */
    public record Envelope(String port, String field, double min, double max) {
        public Envelope {
            Objects.requireNonNull(port, "port");
            Objects.requireNonNull(field, "field");
            if (!(min <= max)) {
                throw new IllegalArgumentException("envelope " + port + "." + field + ": min " + min + " > max " + max);
            }
        }

        /** As written: {@code port.field [min, max]}. */
        @Override
        public String toString() {
            return port + "." + field + " [" + min + ", " + max + "]";
        }
    }

    /**
     * How far every element of numeric field {@code field} of output {@code port} of an update's
     * new version may lie from the running version's value of the same source cycle during its
     * shadow run (D42); beyond it the update is rejected before the switch.
     */
    public record Tolerance(String port, String field, double abs) {
        public Tolerance {
            Objects.requireNonNull(port, "port");
            Objects.requireNonNull(field, "field");
            if (!(abs >= 0) || Double.isInfinite(abs)) {
                throw new IllegalArgumentException("tolerance " + port + "." + field + ": " + abs
                        + " is not a finite number >= 0");
            }
        }

        /** As written: {@code port.field +-abs}. */
        @Override
        public String toString() {
            return port + "." + field + " +-" + abs;
        }
    }

    /** Removes a running (or planned) component. */
    public record Uninstall(String component) implements Step {
        public Uninstall {
            Objects.requireNonNull(component, "component");
        }

        @Override
        public String text() {
            return "uninstall " + component;
        }
    }

    /**
     * Writes a parameter: for a component the set installs, before its half starts (an
     * immutable one too); for a running one, in the switch.
     */
    public record Set(String component, String param, String value) implements Step {
        public Set {
            Objects.requireNonNull(component, "component");
            Objects.requireNonNull(param, "param");
            Objects.requireNonNull(value, "value");
        }

        @Override
        public String text() {
            return "set " + component + " " + param + " " + value;
        }
    }

    private final List<Step> steps;

    private ChangeSet(List<Step> steps) {
        this.steps = List.copyOf(steps);
    }

    /**
     * An update whose window, shadow run, envelopes and tolerances are those given
     * ({@code window}, {@code shadow}: null when not given; envelopes and tolerances by
     * port.field) over the new version's {@code <rollout>} (contract SPEC §12.2) over the
     * defaults: no shadow run, a window of {@code defaultWindow} cycles (D42).
     */
    public static Update rules(String component, org.arflex.contract.Contract contract, Path exe, String from,
                               Long window, Long shadow, List<Envelope> envelopes, List<Tolerance> tolerances,
                               long defaultWindow) {
        return ShadowRules.merged(component, contract, exe, from, window, shadow, envelopes, tolerances, defaultWindow);
    }

    public static Builder builder() {
        return new Builder();
    }

    public List<Step> steps() {
        return steps;
    }

    /** The actions as written, separated by {@code ; }. */
    public String describe() {
        return String.join("; ", steps.stream().map(Step::text).toList());
    }

    @Override
    public String toString() {
        return describe();
    }

    /** Collects the steps of a change set. Not thread-safe. */
    public static final class Builder {
        private final List<Step> steps = new ArrayList<>();

        private Builder() {
        }

        public Builder install(String name, Path exe) {
            steps.add(new Install(name, exe));
            return this;
        }

        public Builder update(String name, org.arflex.contract.Contract contract, Path exe, String from, long window) {
            return update(name, contract, exe, from, window, List.of());
        }

        public Builder update(String name, org.arflex.contract.Contract contract, Path exe, String from, long window,
                              List<Envelope> envelopes) {
            steps.add(new Update(name, contract, exe, from, window, envelopes));
            return this;
        }

        /** An update with a shadow run of {@code shadow} cycles compared by {@code tolerances} (D42). */
        public Builder update(String name, org.arflex.contract.Contract contract, Path exe, String from, long window,
                              List<Envelope> envelopes, long shadow, List<Tolerance> tolerances) {
            steps.add(new Update(name, contract, exe, from, window, envelopes, shadow, tolerances));
            return this;
        }

        /** Adds a step made elsewhere (e.g. {@link ChangeSet#rules}). */
        public Builder add(Step step) {
            steps.add(Objects.requireNonNull(step, "step"));
            return this;
        }

        public Builder uninstall(String name) {
            steps.add(new Uninstall(name));
            return this;
        }

        public Builder set(String name, String param, String value) {
            steps.add(new Set(name, param, value));
            return this;
        }

        public ChangeSet build() {
            return new ChangeSet(steps);
        }
    }
}
