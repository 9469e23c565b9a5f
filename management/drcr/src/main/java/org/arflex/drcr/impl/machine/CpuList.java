package org.arflex.drcr.impl.machine;

import java.util.ArrayList;
import java.util.Collections;
import java.util.List;
import java.util.SortedSet;
import java.util.TreeSet;

/** The kernel's CPU list format ({@code 0-1,4}), as /sys and cgroupfs write it: strict parse and print. */
public final class CpuList {

    /** A bound on CPU numbers, so that a corrupt range cannot make a huge set. */
    static final int MAX_CPU = 8191;

    private CpuList() {
    }

    /**
     * Parses a list like {@code 0-3,6} (an empty text is the empty set).
     *
     * @return the CPUs, ascending
     * @throws IllegalArgumentException saying what part is wrong
     */
    public static SortedSet<Integer> parse(String text) {
        String s = text.strip();
        TreeSet<Integer> out = new TreeSet<>();
        if (s.isEmpty()) {
            return Collections.unmodifiableSortedSet(out);
        }
        for (String part : s.split(",", -1)) {
            int dash = part.indexOf('-');
            int a = number(dash < 0 ? part : part.substring(0, dash), part);
            int b = dash < 0 ? a : number(part.substring(dash + 1), part);
            if (a > b) {
                throw new IllegalArgumentException("CPU range '" + part + "' runs backwards");
            }
            for (int c = a; c <= b; c++) {
                out.add(c);
            }
        }
        return Collections.unmodifiableSortedSet(out);
    }

    private static int number(String digits, String part) {
        if (digits.isEmpty() || digits.length() > 5 || !digits.chars().allMatch(Character::isDigit)) {
            throw new IllegalArgumentException("'" + part + "' is not a CPU number or range (expected e.g. 0,2-3)");
        }
        int n = Integer.parseInt(digits);
        if (n > MAX_CPU) {
            throw new IllegalArgumentException("CPU " + n + " in '" + part + "' is above " + MAX_CPU);
        }
        return n;
    }

    /** {@code 0-1,4}; {@code none} for the empty set. */
    public static String format(java.util.Collection<Integer> cpus) {
        if (cpus.isEmpty()) {
            return "none";
        }
        List<String> parts = new ArrayList<>();
        int start = -1;
        int prev = -2;
        for (int c : new TreeSet<>(cpus)) {
            if (c != prev + 1) {
                if (start >= 0) {
                    parts.add(start == prev ? "" + start : start + "-" + prev);
                }
                start = c;
            }
            prev = c;
        }
        parts.add(start == prev ? "" + start : start + "-" + prev);
        return String.join(",", parts);
    }
}
