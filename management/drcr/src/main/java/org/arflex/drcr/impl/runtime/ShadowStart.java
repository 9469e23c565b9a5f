package org.arflex.drcr.impl.runtime;

import java.io.IOException;
import java.util.List;
import org.arflex.drcr.impl.supervisor.RtHalf;
import org.arflex.planner.Wire;

/**
 * Puts a shadow run's new half to work (D42): bound to the providers its plan gives it (the
 * running version's own providers), then started; no consumer is bound to it, so its outputs
 * are read by nobody but the DRCR. Watched for the runtime's heartbeat as every started half.
 */
final class ShadowStart {

    private ShadowStart() {
    }

    /**
     * Binds and starts {@code nextHalf} of {@code next} at {@code nowNs}.
     *
     * @return why its BIND or START was refused, or null when it runs
     */
    static String begin(Cell cell, Segments segments, Instance next, RtHalf nextHalf, List<Wire> wiring, long nowNs) {
        try {
            Starter.bind(segments, next, nextHalf, wiring);
            nextHalf.runtimeHeartbeat(nowNs);
            nextHalf.start();
        } catch (IOException | RuntimeException e) {
            return "its BIND or START was refused: " + e.getMessage();
        }
        // the runtime's heartbeat goes to it as to every started half; a hang is seen by its
        // cycles (the monitor's hang report finds no instance running this half and kills nothing)
        cell.monitor().watch(next.name, nextHalf, next.contract.fault().heartbeatTimeoutMs(), nowNs);
        return null;
    }
}
