package org.arflex.webconsole.impl;

import static org.junit.jupiter.api.Assertions.assertEquals;

import java.util.List;
import java.util.Map;
import org.junit.jupiter.api.Test;

/**
 * The plan of a set with an update (D51): the load of a CPU while both halves of the update run
 * (its shadow run, its rollback window) is read beside that CPU's final load, and why such a
 * phase is not schedulable is a part of its own; no line of the plan is left over.
 */
class ChangeSetTextTransientTest {

    /** The DRCR's text of a refused update (CellTransientAdmissionTest's cell, Plan.toText). */
    static final String REFUSED = """
            change set: update stage file:/x/stage-1.1.jar
            refused: update 'stage': its shadow run (50 cycles) runs the new half beside the old one: cpu 1: \
            utilisation 1.20 with 'stage (new)' exceeds cap 1.00
            plan: update stage 1.0.0 -> 1.1.0
            actions:
              RESTART  stage  replaced 1.0.0 -> 1.1.0
            stop order: stage
            start order: stage
            wiring:
              stage.x <- src.y
              user.x <- stage.y
            cpus:
              cpu 0  U=0.10/1.00  hyperbolic bound  src, user
              cpu 1  U=0.60/1.00  hyperbolic bound  stage
                shadow (50 cycles)  U=1.20/1.00  not schedulable  stage, stage (new)
                window (1 cycle)  U=0.90/1.00  hyperbolic bound  stage, stage (old)
            memory: 3 MiB of 1 GiB; network: 0 B/s of 1 GB/s
            not schedulable while both halves run:
              update 'stage': its shadow run (50 cycles) runs the new half beside the old one: cpu 1: \
            utilisation 1.20 with 'stage (new)' exceeds cap 1.00
            """;

    @Test
    @SuppressWarnings("unchecked")
    void theLoadWhileBothHalvesRunIsReadBesideItsCpu() {
        Map<String, Object> p = ChangeSetText.parse(REFUSED);
        List<Map<String, Object>> cpus = (List<Map<String, Object>>) p.get("cpus");
        assertEquals(2, cpus.size());
        assertEquals(List.of(), cpus.get(0).get("transient"));
        assertEquals(0.60, cpus.get(1).get("utilisation"));
        assertEquals(List.of(
                Map.of("phase", "shadow", "cycles", 50L, "utilisation", 1.20, "cap", 1.00, "test", "not schedulable",
                        "tasks", List.of("stage", "stage (new)")),
                Map.of("phase", "window", "cycles", 1L, "utilisation", 0.90, "cap", 1.00, "test", "hyperbolic bound",
                        "tasks", List.of("stage", "stage (old)"))),
                cpus.get(1).get("transient"));
        assertEquals(List.of("update 'stage': its shadow run (50 cycles) runs the new half beside the old one: cpu 1: "
                + "utilisation 1.20 with 'stage (new)' exceeds cap 1.00"), p.get("transientRefusals"));
        assertEquals("3 MiB of 1 GiB; network: 0 B/s of 1 GB/s", p.get("memory"));
        assertEquals(List.of(), p.get("after"), "every line of the plan is read into a part");
        assertEquals(REFUSED.substring(REFUSED.indexOf("plan: ")), p.get("planText"));
    }
}
