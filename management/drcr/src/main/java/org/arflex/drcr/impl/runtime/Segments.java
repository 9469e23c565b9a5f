package org.arflex.drcr.impl.runtime;

import java.io.IOException;
import org.arflex.contract.PortSpec;
import org.arflex.contract.PortType;
import org.arflex.contract.PortTypes;
import org.arflex.drcr.impl.abi.PortSegment;
import org.arflex.drcr.impl.supervisor.RtLauncher;

/**
 * The output segments of instances, {@code /arflex.<rid>.<id>.out.<port>} ({@code <id>}: the
 * instance's {@link Instance#objectId}, its name unless a change set updated it): created once per
 * instance before its first start (they survive restarts of the producer, so consumers keep
 * their mapping), with its evaluation-only segments ({@link EvaluationSegments}), and closed when
 * the instance is destroyed or its replaced contract's producer is gone. Actor thread.
 */
final class Segments {

    private final String runtimeId;
    private final PortTypes types;
    private final RtLauncher launcher;
    private final Stops stops;
    private final EvaluationSegments evaluation;
    private final java.util.function.Function<String, String> ids;

    /** @param ids the object id a component's current RT half runs under ({@link Instance#objectId}), by name */
    Segments(String runtimeId, PortTypes types, RtLauncher launcher, Stops stops, EvaluationSegments evaluation,
             java.util.function.Function<String, String> ids) {
        this.runtimeId = runtimeId;
        this.ids = ids;
        this.types = types;
        this.launcher = launcher;
        this.stops = stops;
        this.evaluation = evaluation;
    }

    /**
     * The shm name of a provider's output port, under the object id of the provider's current
     * RT half (its name, or a generation's id after an update in a change set: D38).
     */
    String name(String provider, String port) {
        return objectName(ids.apply(provider), port);
    }

    /** The shm name of an output port of the RT half running under object id {@code id}. */
    String objectName(String id, String port) {
        return "/arflex." + runtimeId + "." + id + ".out." + port;
    }

    /** Creates the segments the instance does not have yet. */
    void ensure(Instance inst) throws IOException {
        if (inst.outputsStale && !stops.stopping(inst)) {
            close(inst); // a replaced contract's segments, their producer gone
            inst.outputsStale = false;
        }
        for (PortSpec p : inst.contract.outputs()) {
            if (inst.outputs.containsKey(p.name())) {
                continue;
            }
            PortType t = types.find(p.type()).orElseThrow(() -> new IOException(
                    "output " + p.name() + ": port type " + p.type() + " is not known to this runtime"));
            int elem = (int) (t.size() + t.maxPayload());
            int method = switch (p.method()) {
                case STATE -> PortSegment.METHOD_STATE;
                case STREAM -> PortSegment.METHOD_STREAM;
                case FRAME -> PortSegment.METHOD_FRAME;
            };
            int overflow = p.overflow() == PortSpec.Overflow.DROP_NEWEST ? PortSegment.OVERFLOW_DROP_NEWEST
                    : PortSegment.OVERFLOW_DROP_OLDEST;
            inst.outputs.put(p.name(), launcher.createOutput(objectName(inst.objectId, p.name()), method, t.name(),
                    t.version().major(), t.version().minor(), elem, Math.max(1, p.depth()), overflow));
        }
        evaluation.ensure(inst, objectName(inst.objectId, EvaluationSegments.PORT));
        StateTransfer.ensure(launcher, types, runtimeId, inst);
    }

    /** Closes (unlinks) every segment of the instance. */
    void close(Instance inst) {
        for (RtLauncher.Output o : inst.outputs.values()) {
            o.close();
        }
        inst.outputs.clear();
        EvaluationSegments.close(inst);
        StateTransfer.close(inst);
    }
}
