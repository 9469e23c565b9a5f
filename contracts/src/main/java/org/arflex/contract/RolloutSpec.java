package org.arflex.contract;

import java.util.List;
import java.util.Objects;
import java.util.OptionalLong;

/**
 * How a new version of this component is taken into a running cell by a change set (SPEC §12.2,
 * docs/DECISIONS.md D38, D42): a shadow run of {@code shadow} cycles on the running version's
 * inputs with its outputs not applied, compared with the running version's outputs field by
 * field within {@code tolerances}; then the switch, and a rollback window of {@code window}
 * cycles in which {@code envelopes} hold. Declared by the version being rolled out; the
 * command line may override each item.
 *
 * @param shadow     cycles of the shadow run, when declared (0: no shadow run)
 * @param window     cycles of the rollback window, when declared (0: committed at the switch)
 * @param tolerances per output field: how far the new version's value may lie from the running one's
 * @param envelopes  per output field: the range its values must stay in
 */
public record RolloutSpec(OptionalLong shadow, OptionalLong window, List<Tolerance> tolerances,
                          List<Envelope> envelopes) {

    /** Largest shadow run or window, in cycles. */
    public static final long MAX_CYCLES = 100_000_000L;

    public RolloutSpec {
        Objects.requireNonNull(shadow, "shadow");
        Objects.requireNonNull(window, "window");
        tolerances = List.copyOf(tolerances);
        envelopes = List.copyOf(envelopes);
    }

    /**
     * Every element of numeric field {@code field} of output {@code port} of the new version may
     * differ from the running version's value of the same source cycle by at most {@code abs}.
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
    }

    /** Every element of numeric field {@code field} of output {@code port} lies in [min, max]. */
    public record Envelope(String port, String field, double min, double max) {
        public Envelope {
            Objects.requireNonNull(port, "port");
            Objects.requireNonNull(field, "field");
            if (!(min <= max)) {
                throw new IllegalArgumentException("envelope " + port + "." + field + ": min " + min + " > max " + max);
            }
        }
    }
}
