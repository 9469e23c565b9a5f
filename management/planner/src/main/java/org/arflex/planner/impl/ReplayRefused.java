package org.arflex.planner.impl;

import org.arflex.planner.CpuAdmissionTest;

/**
 * A CPU rebuilt from a trace refused a task it had accepted in the recorded run: the test
 * does not keep the contract of {@link org.arflex.planner.CpuAdmissionTest} (its state depends on more than the
 * adds), so nothing can be derived from the trace.
 */
final class ReplayRefused extends RuntimeException {
    private static final long serialVersionUID = 1L;

    ReplayRefused(String message) {
        super(message);
    }
}
