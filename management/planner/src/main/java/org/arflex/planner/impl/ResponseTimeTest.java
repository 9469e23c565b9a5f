package org.arflex.planner.impl;

import org.arflex.planner.CpuAdmissionTest;

/**
 * The default {@link CpuAdmissionTest}: fixed priorities, the hyperbolic bound when it applies,
 * else exact response-time analysis ({@link FixedPriorityCpu}).
 */
public final class ResponseTimeTest implements CpuAdmissionTest {

    /** What {@link Cpu#proof()} says when the bound holds. */
    public static final String HYPERBOLIC = "hyperbolic bound";
    /** What {@link Cpu#proof()} says when response-time analysis was needed. */
    public static final String RTA = "response-time analysis";

    @Override
    public Cpu open(int cpu) {
        return new FixedPriorityCpu();
    }

    @Override
    public String toString() {
        return "fixed-priority response-time test";
    }
}
