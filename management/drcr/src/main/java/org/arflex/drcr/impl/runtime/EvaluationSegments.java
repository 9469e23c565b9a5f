package org.arflex.drcr.impl.runtime;

import java.io.IOException;
import java.util.Map;
import org.arflex.contract.Contract;
import org.arflex.drcr.impl.abi.PortSegment;
import org.arflex.drcr.impl.supervisor.RtLauncher;

/**
 * The evaluation-only state segment {@code out.truth} (type eval.GroundTruth 1.0, 192 bytes):
 * created only when the cell runs with {@code arflex.evaluation}, and only for a component whose
 * contract attributes say {@code simulated=true} and {@code role=robot}; the component publishes
 * into it only if it exists. It is never a contract port: no wire and no BIND names it, and
 * evaluation tools map it read-only. It goes with the instance's other output segments.
 */
final class EvaluationSegments {

    static final String PORT = "truth";
    static final String TYPE = "eval.GroundTruth";
    static final int SIZE = 192;

    private final boolean evaluation;
    private final RtLauncher launcher;

    EvaluationSegments(boolean evaluation, RtLauncher launcher) {
        this.evaluation = evaluation;
        this.launcher = launcher;
    }

    /** True when the cell creates the segment for this contract. */
    boolean wanted(Contract c) {
        return evaluation && "true".equals(c.attributes().get("simulated")) && "robot".equals(c.attributes().get("role"));
    }

    /** Creates the segment under {@code shmName} unless the instance has it or does not want it (actor thread). */
    void ensure(Instance inst, String shmName) throws IOException {
        if (!wanted(inst.contract) || inst.evaluationOutputs.containsKey(PORT)) {
            return;
        }
        RtLauncher.Output o = launcher.createOutput(shmName, PortSegment.METHOD_STATE, TYPE, 1, 0, SIZE, 1,
                PortSegment.OVERFLOW_NONE);
        inst.evaluationOutputs.put(PORT, o);
        inst.evaluationSegments = Map.of(PORT, o.name());
    }

    /** Closes (unlinks) the instance's evaluation segments (actor thread). */
    static void close(Instance inst) {
        for (RtLauncher.Output o : inst.evaluationOutputs.values()) {
            o.close();
        }
        inst.evaluationOutputs.clear();
        inst.evaluationSegments = Map.of();
    }
}
