package org.arflex.planner.impl;

import java.util.List;
import org.arflex.planner.CpuAdmissionTest.Task;

/** Response times for refusal messages, where the exact analysis stopped at the deadline. */
final class ResponseTimes {

    private ResponseTimes() {
    }

    /**
     * The exact response time of {@code t} among {@code all} when it is finite and below 100
     * periods, else the last iterate, else -1 (the higher-priority load alone is 1 or more).
     */
    static long forMessage(Task t, List<Task> all, long start) {
        double u = 0;
        for (Task o : all) {
            if (o != t && o.priority() >= t.priority()) {
                u += o.utilisation();
            }
        }
        if (u >= 1) {
            return -1;
        }
        long limit = 100 * t.periodNs();
        long r = Math.max(start, t.wcetNs());
        for (int iter = 0; iter < 10_000; iter++) {
            long next = t.wcetNs();
            for (Task o : all) {
                if (o != t && o.priority() >= t.priority()) {
                    next += ((r + o.periodNs() - 1) / o.periodNs()) * o.wcetNs();
                }
            }
            if (next == r || next > limit) {
                return next;
            }
            r = next;
        }
        return r;
    }
}
