package org.arflex.it;

/**
 * Forward kinematics of the simulated arm's NOMINAL model (simulator/README.md, "The arm"):
 * joints z, y, y, x, y, x; body offsets in the parent frame at q = 0 (all frames aligned with
 * the world there); the TCP 0.30 m along the flange's x axis. Equal to the simulator's
 * NominalKinematics::Tcp (product of exponentials of the same chain). The TRUE TCP error of the
 * cell is |true TCP - tcp(q_ref)|, the definition of the accuracy benchmark.
 */
final class NominalArm {

    private static final double[][] OFFSETS = {
        {0, 0, 0}, {0.35, 0, 0.675}, {0, 0, 1.15}, {0.50, 0, 0.041}, {0.70, 0, 0}, {0.215, 0, 0}};
    private static final char[] AXES = {'z', 'y', 'y', 'x', 'y', 'x'};
    private static final double[] TCP = {0.30, 0, 0};

    private NominalArm() {
    }

    /** The nominal TCP position (m, world frame) at joint angles {@code q} (rad). */
    static double[] tcp(double[] q) {
        double[][] r = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
        double[] p = {0, 0, 0};
        for (int i = 0; i < 6; i++) {
            p = add(p, apply(r, OFFSETS[i]));
            r = mul(r, rot(AXES[i], q[i]));
        }
        return add(p, apply(r, TCP));
    }

    static double distance(double[] a, double[] b) {
        return Math.sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
    }

    private static double[][] rot(char axis, double t) {
        double c = Math.cos(t);
        double s = Math.sin(t);
        return switch (axis) {
            case 'x' -> new double[][] {{1, 0, 0}, {0, c, -s}, {0, s, c}};
            case 'y' -> new double[][] {{c, 0, s}, {0, 1, 0}, {-s, 0, c}};
            default -> new double[][] {{c, -s, 0}, {s, c, 0}, {0, 0, 1}};
        };
    }

    private static double[][] mul(double[][] a, double[][] b) {
        double[][] m = new double[3][3];
        for (int i = 0; i < 3; i++) {
            for (int j = 0; j < 3; j++) {
                for (int k = 0; k < 3; k++) {
                    m[i][j] += a[i][k] * b[k][j];
                }
            }
        }
        return m;
    }

    private static double[] apply(double[][] a, double[] v) {
        double[] r = new double[3];
        for (int i = 0; i < 3; i++) {
            for (int k = 0; k < 3; k++) {
                r[i] += a[i][k] * v[k];
            }
        }
        return r;
    }

    private static double[] add(double[] a, double[] b) {
        return new double[] {a[0] + b[0], a[1] + b[1], a[2] + b[2]};
    }
}
