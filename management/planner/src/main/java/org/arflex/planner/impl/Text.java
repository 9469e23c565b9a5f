package org.arflex.planner.impl;

import java.util.ArrayList;
import java.util.List;
import java.util.Locale;
import org.arflex.planner.Capacities;

/** Formatting of durations, sizes and rates for messages; fixed locale so output is stable. */
public final class Text {

    private Text() {
    }

    /** {@code 1 ms}, {@code 1.20 ms}, {@code 250 us}, {@code 3 s}, {@code 40 ns}. */
    public static String duration(long ns) {
        if (ns >= 1_000_000_000L) {
            return trim(ns / 1e9) + " s";
        }
        if (ns >= 1_000_000L) {
            return trim(ns / 1e6) + " ms";
        }
        if (ns >= 1_000L) {
            return trim(ns / 1e3) + " us";
        }
        return ns + " ns";
    }

    /** {@code 512 MiB}, {@code 1.50 GiB}, {@code 12 KiB}, {@code 100 B}. */
    public static String bytes(long b) {
        if (b >= 1L << 30) {
            return trim(b / (double) (1L << 30)) + " GiB";
        }
        if (b >= 1L << 20) {
            return trim(b / (double) (1L << 20)) + " MiB";
        }
        if (b >= 1L << 10) {
            return trim(b / (double) (1L << 10)) + " KiB";
        }
        return b + " B";
    }

    /** {@code 12 MB/s}, {@code 1.50 kB/s} (decimal units, as network rates are quoted). */
    public static String rate(long bps) {
        if (bps >= 1_000_000_000L) {
            return trim(bps / 1e9) + " GB/s";
        }
        if (bps >= 1_000_000L) {
            return trim(bps / 1e6) + " MB/s";
        }
        if (bps >= 1_000L) {
            return trim(bps / 1e3) + " kB/s";
        }
        return bps + " B/s";
    }

    /** Two decimals, trailing zeros dropped: 1, 1.2, 1.25. */
    public static String trim(double v) {
        String s = String.format(Locale.ROOT, "%.2f", v);
        if (s.indexOf('.') < 0) {
            return s;
        }
        int end = s.length();
        while (s.charAt(end - 1) == '0') {
            end--;
        }
        if (s.charAt(end - 1) == '.') {
            end--;
        }
        return s.substring(0, end);
    }

    /** Utilisation with two decimals: {@code 0.97}. */
    public static String util(double u) {
        return String.format(Locale.ROOT, "%.2f", u);
    }

    /** {@code cpus 0(0.9) 1(0.9), memory 512 MiB, network 10 MB/s}. */
    public static String capacities(Capacities c) {
        List<String> cpus = new ArrayList<>();
        for (Capacities.Cpu cpu : c.cpus()) {
            cpus.add(cpu.id() + "(" + trim(cpu.utilisationCap()) + ")");
        }
        return "cpus " + (cpus.isEmpty() ? "none" : String.join(" ", cpus)) + ", memory " + bytes(c.memoryBytes())
                + ", network " + rate(c.networkBps());
    }
}
