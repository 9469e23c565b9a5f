package org.arflex.planner;

import java.util.List;

/**
 * The CPU load while both halves of an update run side by side (docs/DECISIONS.md D51): in a
 * change set an update's new RT half runs beside the old one for a while, first in its shadow run
 * (D42: the new half on the same inputs, its outputs not applied, before the switch) and then in
 * its rollback window (D38: the old half kept running after the switch). Each half costs its
 * WCET at its priority on the CPU it runs on, whether its outputs are applied or not. Planned
 * for a {@link Change} that names the update with {@link Change.Builder#overlap}; one per phase
 * that has a second half on some CPU.
 *
 * @param phase      which phase
 * @param cycles     how long it lasts: the longest of its updates', in cycles of the new version
 * @param components the updated components whose second half runs in this phase, by name
 * @param cpus       the CPUs a second half runs on, by id: every task there in this phase (the
 *                   second half named {@code "<component> (new)"} or {@code "<component> (old)"}),
 *                   the utilisation of them all, and what proves them schedulable, or
 *                   {@link #NOT_SCHEDULABLE}
 * @param refusals   one sentence per CPU where the phase is not schedulable, naming the update,
 *                   the phase, the CPU and the figures; empty when it is
 */
public record TransientLoad(Phase phase, long cycles, List<String> components, List<CpuLoad> cpus,
        List<String> refusals) {

    /** What {@link CpuLoad#test()} says of a CPU whose tasks in this phase are not schedulable. */
    public static final String NOT_SCHEDULABLE = "not schedulable";

    /** When both halves of an update run. */
    public enum Phase {
        /** Before the switch: the running configuration plus each new half in its shadow run. */
        SHADOW,
        /** After the switch: the configuration of the plan plus each old half kept for its window. */
        WINDOW;

        /** {@code shadow} or {@code window}, as the plan's text writes it. */
        public String label() {
            return this == SHADOW ? "shadow" : "window";
        }
    }

    public TransientLoad {
        components = List.copyOf(components);
        cpus = List.copyOf(cpus);
        refusals = List.copyOf(refusals);
    }

    /** True when every CPU of this phase is schedulable. */
    public boolean admitted() {
        return refusals.isEmpty();
    }
}
