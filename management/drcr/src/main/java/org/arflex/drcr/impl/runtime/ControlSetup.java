package org.arflex.drcr.impl.runtime;

import java.util.ArrayList;
import java.util.List;
import java.util.Optional;
import org.arflex.contract.Contract;
import org.arflex.contract.FaultPolicy;
import org.arflex.contract.PropertySpec;
import org.arflex.drcr.impl.abi.ControlBlock;

/** What a contract writes into the control block of its RT half: the configuration and the parameter table. */
final class ControlSetup {

    private ControlSetup() {
    }

    /**
     * The control block's configuration of an instance. A service (best effort, SCHED_OTHER, no
     * deadline) does not lock its memory: locking buys it nothing, and locking and unlocking a
     * large process (a MuJoCo/OSMesa camera, 256 MiB) at its start and exit stalled the 1 ms
     * components of the cell for several periods each time (./arflex bench cell, docs/DECISIONS.md D8).
     */
    static ControlBlock.Config config(Contract c, int cpu, boolean noMlock) {
        boolean service = c.taskType() == Contract.TaskType.SERVICE;
        int flags = (c.movesHardware() ? ControlBlock.CFG_MOVES_HARDWARE : 0)
                | (noMlock || service ? ControlBlock.CFG_NO_MLOCK : 0);
        int taskType = switch (c.taskType()) {
            case PERIODIC -> 0;
            case SPORADIC -> 1;
            case SERVICE -> 2;
        };
        return new ControlBlock.Config(c.timing().periodNs(), c.timing().deadlineNs(),
                c.fault().heartbeatTimeoutMs() * 1_000_000L, cpu >= 0 ? 1L << cpu : 0L,
                c.taskType() == Contract.TaskType.SERVICE ? 0 : c.timing().priority(), taskType,
                c.fault().safeOutput() == FaultPolicy.SafeOutput.ZERO ? 1 : 0, flags,
                c.fault().orphanHoldMs() * 1_000_000L);
    }

    /** The parameter table: every property of the contract with its bounds and configured value bits. */
    static List<ControlBlock.Param> params(Contract c, long[] values) {
        List<ControlBlock.Param> out = new ArrayList<>();
        for (int i = 0; i < c.properties().size(); i++) {
            PropertySpec p = c.properties().get(i);
            int type = switch (p.type()) {
                case BOOL -> ControlBlock.PARAM_BOOL;
                case INT -> ControlBlock.PARAM_INT64;
                case DOUBLE -> ControlBlock.PARAM_DOUBLE;
            };
            long min = bound(p, p.min(), true);
            long max = bound(p, p.max(), false);
            out.add(new ControlBlock.Param(p.name(), type, p.mutable(), min, max, values[i]));
        }
        return out;
    }

    private static long bound(PropertySpec p, Optional<Double> b, boolean lower) {
        return switch (p.type()) {
            case BOOL -> lower ? 0 : 1;
            case INT -> b.map(Double::longValue).orElse(lower ? Long.MIN_VALUE : Long.MAX_VALUE);
            case DOUBLE -> Double.doubleToRawLongBits(b.orElse(lower ? -Double.MAX_VALUE : Double.MAX_VALUE));
        };
    }
}
