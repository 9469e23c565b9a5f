package org.arflex.drcr.impl.runtime;

import org.arflex.contract.Contract;
import org.arflex.contract.PortSpec;
import org.arflex.contract.PortType;
import org.arflex.contract.PortTypes;
import org.arflex.contract.RolloutSpec;

/**
 * The shadow run's rules of an update (D42): checked when the set is planned, and merged from
 * the new version's contract ({@code <rollout>}, SPEC §12.2) with what the command line gives.
 */
final class ShadowRules {

    private ShadowRules() {
    }

    /**
     * Why the tolerances of {@code u} cannot be compared, or null: each names an output of the
     * new version whose numeric field exists, and the running version ({@code running}) has that
     * output with the same port type; tolerances need a shadow run.
     */
    static String problem(PortTypes types, Contract running, ChangeSet.Update u) {
        if (!u.tolerances().isEmpty() && u.shadow() == 0) {
            return "tolerance " + u.tolerances().get(0) + ": tolerances compare a shadow run, and none is declared "
                    + "(shadow <cycles>, or <rollout shadow> in the contract)";
        }
        for (ChangeSet.Tolerance t : u.tolerances()) {
            PortSpec mine = u.contract().outputs().stream().filter(p -> p.name().equals(t.port())).findFirst().orElse(null);
            if (mine == null) {
                return "tolerance " + t + ": the new version has no output '" + t.port() + "'";
            }
            PortType type = types.find(mine.type()).orElse(null);
            PortType.Field f = type == null ? null : type.field(t.field()).orElse(null);
            if (f == null || f.padding()) {
                return "tolerance " + t + ": port type " + mine.type() + " has no field '" + t.field() + "'";
            }
            if (f.scalar() == PortType.Scalar.U8 && f.count() > 1) {
                return "tolerance " + t + ": field '" + t.field() + "' of " + mine.type() + " is bytes, not a number";
            }
            PortSpec theirs = running.outputs().stream().filter(p -> p.name().equals(t.port())).findFirst().orElse(null);
            if (theirs == null || !theirs.type().equals(mine.type())) {
                return "tolerance " + t + ": the running version has no output '" + t.port() + "' of type "
                        + mine.type() + " to compare with";
            }
        }
        return null;
    }

    /**
     * The update's rules: what the command line gave ({@code shadow}, {@code window}: null when
     * not given; tolerances and envelopes by port.field) over what the new version's contract
     * declares, over the defaults (no shadow run, a window of {@code defaultWindow}).
     */
    static ChangeSet.Update merged(String component, Contract contract, java.nio.file.Path exe, String from,
                                   Long window, Long shadow, java.util.List<ChangeSet.Envelope> envelopes,
                                   java.util.List<ChangeSet.Tolerance> tolerances, long defaultWindow) {
        RolloutSpec r = contract.rollout().orElse(null);
        long w = window != null ? window : r != null && r.window().isPresent() ? r.window().getAsLong() : defaultWindow;
        long k = shadow != null ? shadow : r != null && r.shadow().isPresent() ? r.shadow().getAsLong() : 0;
        java.util.Map<String, ChangeSet.Tolerance> tol = new java.util.LinkedHashMap<>();
        java.util.Map<String, ChangeSet.Envelope> env = new java.util.LinkedHashMap<>();
        if (r != null) {
            for (RolloutSpec.Tolerance t : r.tolerances()) {
                tol.put(t.port() + "." + t.field(), new ChangeSet.Tolerance(t.port(), t.field(), t.abs()));
            }
            for (RolloutSpec.Envelope e : r.envelopes()) {
                env.put(e.port() + "." + e.field(), new ChangeSet.Envelope(e.port(), e.field(), e.min(), e.max()));
            }
        }
        for (ChangeSet.Tolerance t : tolerances) {
            tol.put(t.port() + "." + t.field(), t);
        }
        for (ChangeSet.Envelope e : envelopes) {
            env.put(e.port() + "." + e.field(), e);
        }
        return new ChangeSet.Update(component, contract, exe, from, w, java.util.List.copyOf(env.values()), k,
                java.util.List.copyOf(tol.values()));
    }
}
