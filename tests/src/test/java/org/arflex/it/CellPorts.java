package org.arflex.it;

import java.io.IOException;
import java.nio.ByteBuffer;
import java.nio.ByteOrder;
import java.nio.MappedByteBuffer;
import java.nio.channels.FileChannel;
import java.nio.file.Path;
import java.nio.file.StandardOpenOption;
import org.arflex.drcr.impl.abi.Layout;

/**
 * Read-only views of the cell's state ports in shared memory (rt-core ABI: slot 0 after the segment
 * header, its slot header's first word the seqlock, odd while the writer writes, then the value;
 * offsets from the generated {@link Layout}, see Ports). Records of the port types used by CellE2EIT: the
 * field offsets are those of contracts/types (arflex.JointRef, arflex.JointState, arflex.Sample)
 * and of the simulator's evaluation-only eval.GroundTruth (simulator/README.md, "Ground truth").
 */
final class CellPorts {

    private CellPorts() {
    }

    /** One state port mapped once; {@link #read()} copies a consistent value or returns null. */
    static final class State implements AutoCloseable {
        private final FileChannel ch;
        private final MappedByteBuffer b;
        private final int size;

        State(Path segment, int size) throws IOException {
            this.size = size;
            ch = FileChannel.open(segment, StandardOpenOption.READ);
            b = ch.map(FileChannel.MapMode.READ_ONLY, 0, Ports.SLOT0_VALUE + size);
            b.order(ByteOrder.LITTLE_ENDIAN);
        }

        /** The current value (little endian), or null: never written, or torn on every attempt. */
        ByteBuffer read() {
            byte[] v = new byte[size];
            for (int attempt = 0; attempt < 1000; attempt++) {
                long s1 = b.getLong(Ports.SLOT0_SEQ);
                if (s1 == 0) {
                    return null;
                }
                if ((s1 & 1) != 0) {
                    Thread.onSpinWait();
                    continue;
                }
                b.get(Ports.SLOT0_VALUE, v);
                if (b.getLong(Ports.SLOT0_SEQ) == s1) {
                    return ByteBuffer.wrap(v).order(ByteOrder.LITTLE_ENDIAN);
                }
            }
            return null;
        }

        @Override
        public void close() throws IOException {
            ch.close();
        }
    }

    /** arflex.JointRef 1.0 / the first fields of arflex.JointState 1.0: t_ns, seq, q[6] (qd[6]). */
    record Joints(long tNs, long seq, double[] q, double[] qd) {
        static Joints of(ByteBuffer v, boolean withVelocity) {
            if (v == null) {
                return null;
            }
            double[] q = new double[6];
            double[] qd = new double[6];
            for (int i = 0; i < 6; i++) {
                q[i] = v.getDouble(16 + 8 * i);
                if (withVelocity) {
                    qd[i] = v.getDouble(64 + 8 * i);
                }
            }
            return new Joints(v.getLong(0), v.getLong(8), q, qd);
        }

        double maxAbsVelocity() {
            double m = 0;
            for (double d : qd) {
                m = Math.max(m, Math.abs(d));
            }
            return m;
        }

        double maxAbsDiff(Joints o) {
            double m = 0;
            for (int i = 0; i < 6; i++) {
                m = Math.max(m, Math.abs(q[i] - o.q[i]));
            }
            return m;
        }
    }

    /** arflex.Sample 1.0: seq, t_ns, value. */
    record Sample(long seq, long tNs, double value) {
        static Sample of(ByteBuffer v) {
            return v == null ? null : new Sample(v.getLong(0), v.getLong(8), v.getDouble(16));
        }
    }

    /** eval.GroundTruth 1.0 (192 bytes): seq at 8, cycles at 24, the TRUE TCP position at 40. */
    record Truth(long seq, long cycles, double[] p) {
        static Truth of(ByteBuffer v) {
            if (v == null) {
                return null;
            }
            return new Truth(v.getLong(8), v.getLong(24), new double[] {v.getDouble(40), v.getDouble(48), v.getDouble(56)});
        }
    }

    /** ctl.flags bits (rt-core/include/arflex/control.h): safe hook running, operator reset needed. */
    static final int FLAG_SAFE_ACTIVE = Layout.FLAG_SAFE_ACTIVE;
    static final int FLAG_RESET_REQUIRED = Layout.FLAG_RESET_REQUIRED;
    static final int FLAG_SUPERVISOR_LOST = Layout.FLAG_SUPERVISOR_LOST;

    /** The RT half's flags word of a control block segment (ctl.flags), or 0 when it is gone. */
    static int ctlFlags(Path ctl) {
        try (FileChannel ch = FileChannel.open(ctl, StandardOpenOption.READ)) {
            ByteBuffer b = ByteBuffer.allocate(4).order(ByteOrder.LITTLE_ENDIAN);
            if (ch.read(b, Layout.OFF_CTL_FLAGS) != 4) {
                return 0;
            }
            return b.getInt(0);
        } catch (IOException e) {
            return 0;
        }
    }

    static final int JOINT_REF = 64;
    static final int JOINT_STATE = 160;
    static final int SAMPLE = 24;
    static final int TRUTH = 192;
}
