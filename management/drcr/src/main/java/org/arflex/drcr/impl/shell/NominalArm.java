package org.arflex.drcr.impl.shell;

/**
 * Forward kinematics of the simulated arm's nominal model (simulator/README.md, "The arm"):
 * joints about z, y, y, x, y, x; each body's offset in its parent's frame at q = 0, where every
 * frame is aligned with the world; the tool centre point 0.30 m along the flange's x axis. The
 * summary's TRUE TCP error is the distance of the true TCP from this model at the program's
 * reference (the accuracy benchmark's definition). The integration tests use this one too.
 */
public final class NominalArm {

    private static final double[][] OFFSETS = {
        {0, 0, 0}, {0.35, 0, 0.675}, {0, 0, 1.15}, {0.50, 0, 0.041}, {0.70, 0, 0}, {0.215, 0, 0}};
    private static final char[] AXES = {'z', 'y', 'y', 'x', 'y', 'x'};
    private static final double[] TCP = {0.30, 0, 0};

    private NominalArm() {
    }

    /** The nominal TCP position (m, world frame) at joint angles {@code q} (rad, 6 of them). */
    public static double[] tcp(double[] q) {
        double[][] r = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
        double[] p = {0, 0, 0};
        for (int j = 0; j < AXES.length; j++) {
            p = plus(p, times(r, OFFSETS[j]));
            r = times(r, rotation(AXES[j], q[j]));
        }
        return plus(p, times(r, TCP));
    }

    /** The distance (m) between two points. */
    public static double distance(double[] a, double[] b) {
        return Math.sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
    }

    private static double[][] rotation(char axis, double angle) {
        double c = Math.cos(angle);
        double s = Math.sin(angle);
        return switch (axis) {
            case 'x' -> new double[][] {{1, 0, 0}, {0, c, -s}, {0, s, c}};
            case 'y' -> new double[][] {{c, 0, s}, {0, 1, 0}, {-s, 0, c}};
            default -> new double[][] {{c, -s, 0}, {s, c, 0}, {0, 0, 1}};
        };
    }

    private static double[][] times(double[][] a, double[][] b) {
        double[][] m = new double[3][];
        for (int i = 0; i < 3; i++) {
            m[i] = times(b, a[i], true);
        }
        return m;
    }

    private static double[] times(double[][] a, double[] v) {
        return times(a, v, false);
    }

    /** {@code a v}, or with {@code transposed} the row vector {@code v a}. */
    private static double[] times(double[][] a, double[] v, boolean transposed) {
        double[] r = new double[3];
        for (int i = 0; i < 3; i++) {
            for (int k = 0; k < 3; k++) {
                r[i] += (transposed ? a[k][i] : a[i][k]) * v[k];
            }
        }
        return r;
    }

    private static double[] plus(double[] a, double[] b) {
        return new double[] {a[0] + b[0], a[1] + b[1], a[2] + b[2]};
    }
}
