package org.arflex.apicheck;

/** OSGi versions as {@code major.minor.micro} ints (a qualifier is ignored). */
final class Versions {

    private Versions() {
    }

    static int[] parse(String v) {
        String[] f = v.split("\\.");
        int[] out = new int[3];
        for (int i = 0; i < 3 && i < f.length; i++) {
            out[i] = Integer.parseInt(f[i]);
        }
        return out;
    }

    static int compare(int[] a, int[] b) {
        for (int i = 0; i < 3; i++) {
            if (a[i] != b[i]) {
                return Integer.compare(a[i], b[i]);
            }
        }
        return 0;
    }
}
