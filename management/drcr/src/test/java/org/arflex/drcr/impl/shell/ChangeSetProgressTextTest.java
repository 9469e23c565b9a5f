package org.arflex.drcr.impl.shell;

import static org.junit.jupiter.api.Assertions.assertEquals;

import org.arflex.drcr.dto.ChangeSetProgressDTO;
import org.junit.jupiter.api.Test;

/** {@code arflex:change progress} (D53): a running apply in its shadow run, a finished one, none. */
class ChangeSetProgressTextTest {

    private static ChangeSetProgressDTO shadow() {
        ChangeSetProgressDTO p = new ChangeSetProgressDTO();
        p.actions = new String[] {"update stage file:/x.jar", "set user gain 2"};
        p.running = true;
        p.phase = "shadow";
        p.phases = new String[] {"checking", "preparing", "shadow"};
        p.step = "update stage: shadow run of pid 7, cycle 40 of 100";
        p.component = "stage";
        p.cycle = 40;
        p.cycles = 100;
        p.worstField = "y.value";
        p.worstDeviation = 0.004;
        p.tolerance = 0.01;
        p.startedMillis = 10_000;
        p.phaseMillis = 11_500;
        return p;
    }

    @Test
    void aRunningApplySaysItsPhaseCyclesAndWorstDeviation() {
        assertEquals("change set: update stage file:/x.jar; set user gain 2\n"
                + "applying: shadow for 0.5 s (began 2.0 s ago; phases checking > preparing > shadow)\n"
                + "now: update stage: shadow run of pid 7, cycle 40 of 100\n"
                + "cycles: 40 of 100 (stage)\n"
                + "worst deviation so far: y.value 0.00400 (tolerance 0.01)", ChangeSetProgressText.of(shadow(), 12_000));
    }

    @Test
    void aFinishedApplySaysItsOutcome() {
        ChangeSetProgressDTO p = shadow();
        p.running = false;
        p.phase = "done";
        p.phases = new String[] {"checking", "preparing", "shadow", "done"};
        p.phaseMillis = 12_000;
        p.outcome = "rejected-in-shadow";
        p.why = "update stage: rejected in shadow after 40 cycles: it exited";
        assertEquals("change set: update stage file:/x.jar; set user gain 2\n"
                + "finished 0.5 s ago, after 2.0 s (phases checking > preparing > shadow > done)\n"
                + "outcome: rejected-in-shadow: update stage: rejected in shadow after 40 cycles: it exited",
                ChangeSetProgressText.of(p, 12_500));
    }

    @Test
    void noApplyYet() {
        assertEquals("no change set was applied in this runtime", ChangeSetProgressText.of(null, 0));
    }
}
