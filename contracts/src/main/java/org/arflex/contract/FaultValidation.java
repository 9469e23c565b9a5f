package org.arflex.contract;

import static org.arflex.contract.ContractValidator.MAX_INTENSITY;

import org.arflex.contract.internal.ContractXml;
import org.arflex.contract.internal.Located;

/**
 * SPEC §11: checks a contract's {@code <fault>} policy (restart, safe output, intensity, times,
 * heartbeat against the period); called by {@link ContractValidator}, reports into its {@link Problems}.
 */
final class FaultValidation {
    private FaultValidation() {
    }

    static FaultPolicy check(Problems p, ContractXml x, Timing timing, Contract.TaskType task) {
        ContractXml.Fault f = x.fault;
        if (f == null) {
            p.at(x, "11", "fault", "required element <fault> is missing");
            return null;
        }
        boolean ok = true;
        FaultPolicy.Restart restart = null;
        if (f.restart == null) {
            p.at(f, "11", "fault/@restart", "required attribute is missing (permanent, transient or temporary)");
            ok = false;
        } else {
            switch (f.restart) {
                case "permanent" -> restart = FaultPolicy.Restart.PERMANENT;
                case "transient" -> restart = FaultPolicy.Restart.TRANSIENT;
                case "temporary" -> restart = FaultPolicy.Restart.TEMPORARY;
                default -> {
                    p.at(f, "11", "fault/@restart", "'" + f.restart + "' is not permanent, transient or temporary");
                    ok = false;
                }
            }
        }
        FaultPolicy.SafeOutput safe = null;
        if (f.safe == null) {
            p.at(f, "11", "fault/@safe", "required attribute is missing (hold or zero)");
            ok = false;
        } else if ("hold".equals(f.safe)) {
            safe = FaultPolicy.SafeOutput.HOLD;
        } else if ("zero".equals(f.safe)) {
            safe = FaultPolicy.SafeOutput.ZERO;
        } else {
            p.at(f, "11", "fault/@safe", "'" + f.safe + "' is not hold or zero");
            ok = false;
        }
        int intensity = 3;
        if (f.intensity != null) {
            Integer i = Values.integer(f.intensity);
            if (i == null || i < 0 || i > MAX_INTENSITY) {
                p.at(f, "11", "fault/@intensity", "'" + f.intensity + "' is not an integer 0.." + MAX_INTENSITY);
                ok = false;
            } else {
                intensity = i;
            }
        }
        Long window = millis(p, f, f.window, "fault/@window", 10_000, 1, 3_600_000);
        Long backoff = millis(p, f, f.backoff, "fault/@backoff", 100, 0, 60_000);
        Long heartbeat = millis(p, f, f.heartbeatTimeout, "fault/@heartbeatTimeout", 100, 1, 60_000);
        Long orphanHold = millis(p, f, f.orphanHold, "fault/@orphanHold", FaultPolicy.DEFAULT_ORPHAN_HOLD_MS, 0, 60_000);
        if (window == null || backoff == null || heartbeat == null || orphanHold == null) {
            ok = false;
        }
        if (heartbeat != null && timing != null && task != Contract.TaskType.SERVICE
                && heartbeat * 1_000_000L < timing.periodNs()) {
            p.at(f, "11", "fault/@heartbeatTimeout", "heartbeat timeout " + Values.formatDuration(heartbeat * 1_000_000L)
                    + " is shorter than the period " + Values.formatDuration(timing.periodNs()));
            ok = false;
        }
        return ok ? new FaultPolicy(restart, intensity, window, backoff, safe, heartbeat, orphanHold) : null;
    }

    private static Long millis(Problems p, Located node, String text, String field, long dflt, long min, long max) {
        if (text == null) {
            return dflt;
        }
        Long ns = Values.durationNs(text);
        if (ns == null) {
            p.at(node, "8.1", field, "'" + text + "' is not a duration (integer with unit ns, us, ms or s, e.g. 100ms)");
            return null;
        }
        if (ns % 1_000_000L != 0) {
            p.at(node, "11", field, "'" + text + "' is not a whole number of milliseconds");
            return null;
        }
        long ms = ns / 1_000_000L;
        if (ms < min || ms > max) {
            p.at(node, "11", field, "'" + text + "' is out of range " + Values.formatDuration(min * 1_000_000L) + ".."
                    + Values.formatDuration(max * 1_000_000L));
            return null;
        }
        return ms;
    }
}
