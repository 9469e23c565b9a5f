package org.arflex.drcr.impl.runtime;

import java.io.IOException;
import java.util.ArrayList;
import java.util.EnumSet;
import java.util.List;
import java.util.Map;
import java.util.Optional;
import org.arflex.contract.Contract;
import org.arflex.contract.PortSpec;
import org.arflex.contract.PortType;
import org.arflex.contract.TypeVersion;
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
    /**
     * The record's fields in the order of simulator/include/arflex_sim/ground_truth.h, for the
     * DRCR's port reader to decode them by name ({@code arflex:summary} reads {@code p}); offsets
     * follow from the order (each scalar aligned to its size), as for a contract port type.
     */
    private static final Object[][] TRUTH_FIELDS = {
        {"t_ns", PortType.Scalar.I64, 1, "ns"}, {"seq", PortType.Scalar.U64, 1, ""},
        {"steps", PortType.Scalar.U64, 1, ""}, {"cycles", PortType.Scalar.U64, 1, ""},
        {"sim_time", PortType.Scalar.F64, 1, "s"}, {"p", PortType.Scalar.F64, 3, "m"},
        {"quat", PortType.Scalar.F64, 4, ""}, {"deflection", PortType.Scalar.F64, 6, "rad"},
        {"ext_force", PortType.Scalar.F64, 3, "N"}, {"obstacle_contacts", PortType.Scalar.U32, 1, ""},
        {"safe", PortType.Scalar.U32, 1, ""}, {"warnings", PortType.Scalar.U32, 1, ""},
        {"pad0", PortType.Scalar.U32, 1, ""}, {"reserved", PortType.Scalar.U64, 1, ""}};
    /** eval.GroundTruth 1.0 as a port type (not one of the contract types: PortTypes refuses the eval. namespace). */
    static final PortType TRUTH_TYPE = truthType();
    /** The segment as an output of a state port, for the port reader. */
    static final PortSpec TRUTH_SPEC = new PortSpec(PORT, PortSpec.Direction.OUT, TYPE, new TypeVersion(1, 0),
            PortSpec.Method.STATE, 1, PortSpec.Overflow.DROP_OLDEST, Optional.empty(), false);

    private final boolean evaluation;
    private final RtLauncher launcher;

    EvaluationSegments(boolean evaluation, RtLauncher launcher) {
        this.evaluation = evaluation;
        this.launcher = launcher;
    }

    private static PortType truthType() {
        List<PortType.Field> fields = new ArrayList<>();
        int at = 0;
        for (Object[] f : TRUTH_FIELDS) {
            PortType.Scalar s = (PortType.Scalar) f[1];
            int count = (Integer) f[2];
            at = (at + s.size() - 1) / s.size() * s.size();
            fields.add(new PortType.Field((String) f[0], s, count, count > 1, at, false, (String) f[3], "", null));
            at += s.size() * count;
        }
        if (at != SIZE) {
            throw new IllegalStateException(TYPE + ": the fields take " + at + " bytes, not " + SIZE);
        }
        return new PortType(TYPE, new TypeVersion(1, 0), EnumSet.of(PortSpec.Method.STATE), fields, List.of(), SIZE, 0,
                "the simulator's evaluation-only ground truth", "simulator/include/arflex_sim/ground_truth.h");
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
