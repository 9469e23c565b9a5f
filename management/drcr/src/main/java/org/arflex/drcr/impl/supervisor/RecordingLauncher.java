package org.arflex.drcr.impl.supervisor;

import java.io.IOException;

/**
 * A launcher that records every RT half it spawned in {@link HalfRecords} and removes the
 * record when the half was reaped (D79). A half is recorded once it is READY: one whose runtime
 * dies before is not, and leaves by itself at the end of its orphan hold (ABI.md 6.2).
 */
public final class RecordingLauncher implements RtLauncher {

    private final RtLauncher inner;
    private final HalfRecords records;

    public RecordingLauncher(RtLauncher inner, HalfRecords records) {
        this.inner = inner;
        this.records = records;
    }

    @Override
    public RtHalf launch(Spec spec) throws IOException {
        RtHalf half = inner.launch(spec);
        long pid = half.pid();
        records.spawned(spec.runtimeId(), spec.instance(), pid);
        half.exit().whenComplete((x, e) -> records.exited(spec.runtimeId(), spec.instance(), pid));
        return half;
    }

    @Override
    public Output createOutput(String segmentName, int method, String typeName, int major, int minor, int elemSize,
                               int depth, int overflow) throws IOException {
        return inner.createOutput(segmentName, method, typeName, major, minor, elemSize, depth, overflow);
    }
}
