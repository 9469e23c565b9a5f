package org.arflex.drcr.impl.supervisor;

import java.io.IOException;
import java.nio.file.Path;
import java.util.List;
import org.arflex.drcr.impl.abi.ControlBlock;

/**
 * Creates the shared objects of an instance and spawns its RT half. The real one is
 * {@link ProcessLauncher}; tests use a fake.
 */
public interface RtLauncher {

    /** Everything needed to spawn one RT half. */
    record Spec(String runtimeId, String instance, Path executable, ControlBlock.Config config,
                List<ControlBlock.Param> params, boolean resetRequired, long readyTimeoutMs) {
    }

    /**
     * Creates ctl, cmd and rsp, spawns {@code <exe> --runtime <rid> --instance <inst>} and waits
     * for the RT half to report READY. On any failure everything created is removed and the
     * process is gone.
     *
     * @throws IOException with the reason (exit status, the RT half's error, its last stderr)
     */
    RtHalf launch(Spec spec) throws IOException;

    /** Output segments stay with the instance across restarts of its RT half. */
    interface Output extends AutoCloseable {
        /** Segment name. */
        String name();

        /** Elements published by the producer. */
        long published();

        /**
         * The newest value's payload ({@code bytes} bytes of port type {@code typeName}), or
         * null when none was written yet; any thread.
         *
         * @throws IOException when the segment cannot be read
         */
        default byte[] newest(String typeName, int bytes) throws IOException {
            org.arflex.drcr.impl.abi.PortReader.Value v = org.arflex.drcr.impl.abi.PortReader.readNewest(name(), typeName,
                    bytes);
            return v.index() < 0 ? null : v.payload();
        }

        /** Why the segment is damaged (truncated, header overwritten), or null when intact. */
        default String damage() {
            return null;
        }

        @Override
        void close();
    }

    /** Creates the segment of one output port. */
    Output createOutput(String segmentName, int method, String typeName, int major, int minor, int elemSize,
                        int depth, int overflow) throws IOException;
}
