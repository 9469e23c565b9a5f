package org.arflex.drcr.impl.shell;

import static org.junit.jupiter.api.Assertions.assertEquals;

import org.arflex.drcr.dto.ChangeSetProgressDTO;
import org.arflex.drcr.dto.UpdateProgressDTO;
import org.junit.jupiter.api.Test;

/**
 * {@code arflex:change progress} (D53): a running apply in its shadow run, a finished one, none;
 * a set of two updates, a line for each (D60), and of one, the same text as without entries.
 */
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

    private static UpdateProgressDTO entry(String component, String phase, long cycle, long cycles, String worstField,
                                           double worst, String verdict) {
        UpdateProgressDTO u = new UpdateProgressDTO();
        u.component = component;
        u.phase = phase;
        u.cycle = cycle;
        u.cycles = cycles;
        u.worstField = worstField;
        u.worstDeviation = worst;
        u.tolerance = worstField == null ? 0 : 0.01;
        u.verdict = verdict;
        return u;
    }

    @Test
    void aSetOfOneUpdateSaysWhatItSaidBeforeItsEntry() {
        ChangeSetProgressDTO p = shadow();
        p.updates = new UpdateProgressDTO[] {entry("stage", "shadow", 40, 100, "y.value", 0.004, null)};
        assertEquals(ChangeSetProgressText.of(shadow(), 12_000), ChangeSetProgressText.of(p, 12_000));
    }

    @Test
    void aRunningSetOfTwoUpdatesSaysEachOnItsOwnLine() {
        ChangeSetProgressDTO p = shadow();
        p.actions = new String[] {"update src file:/s.jar", "update stage file:/x.jar"};
        p.updates = new UpdateProgressDTO[] {entry("src", "window", 20, 40, "y.value", 0.002, null),
                entry("stage", "shadow", 40, 100, "y.value", 0.004, null)};
        assertEquals("change set: update src file:/s.jar; update stage file:/x.jar\n"
                + "applying: shadow for 0.5 s (began 2.0 s ago; phases checking > preparing > shadow)\n"
                + "now: update stage: shadow run of pid 7, cycle 40 of 100\n"
                + "update src: rollback window, cycle 20 of 40, worst deviation in shadow y.value 0.00200 (tolerance 0.01)\n"
                + "update stage: shadow run, cycle 40 of 100, worst deviation in shadow y.value 0.00400 (tolerance 0.01)",
                ChangeSetProgressText.of(p, 12_000));
        p.updates[1] = entry("stage", null, 0, 0, null, 0, null);
        assertEquals("update stage: not in a shadow run or window yet",
                ChangeSetProgressText.of(p, 12_000).lines().reduce((a, b) -> b).orElseThrow());
    }

    @Test
    void aFinishedSetOfTwoUpdatesSaysEachOnesLastCountersAndVerdict() {
        ChangeSetProgressDTO p = shadow();
        p.actions = new String[] {"update src file:/s.jar", "update stage file:/x.jar"};
        p.running = false;
        p.phase = "done";
        p.phases = new String[] {"checking", "preparing", "shadow", "done"};
        p.phaseMillis = 12_000;
        p.outcome = "rejected-in-shadow";
        p.why = "update stage: rejected in shadow after 40 cycles: it exited";
        p.updates = new UpdateProgressDTO[] {entry("src", "shadow", 60, 100, "y.value", 0.002, "cancelled"),
                entry("stage", "shadow", 40, 100, null, 0, "rejected-in-shadow")};
        p.updates[0].why = "cancelled: update stage was rejected in shadow (it exited)";
        assertEquals("change set: update src file:/s.jar; update stage file:/x.jar\n"
                + "finished 0.5 s ago, after 2.0 s (phases checking > preparing > shadow > done)\n"
                + "outcome: rejected-in-shadow: update stage: rejected in shadow after 40 cycles: it exited\n"
                + "update src: shadow run, cycle 60 of 100, worst deviation in shadow y.value 0.00200 (tolerance 0.01); "
                + "cancelled: update stage was rejected in shadow (it exited)\n"
                + "update stage: shadow run, cycle 40 of 100; rejected-in-shadow", ChangeSetProgressText.of(p, 12_500));
        // a set torn down gives neither update a verdict of its own
        p.outcome = "torn-down";
        p.updates = new UpdateProgressDTO[] {entry("src", "shadow", 60, 100, null, 0, null),
                entry("stage", null, 0, 0, null, 0, null)};
        assertEquals("update src: shadow run, cycle 60 of 100; no verdict of its own\n"
                + "update stage: no shadow run or window; no verdict of its own", String.join("\n",
                ChangeSetProgressText.of(p, 12_500).lines().skip(3).toList()));
    }

    @Test
    void noApplyYet() {
        assertEquals("no change set was applied in this runtime", ChangeSetProgressText.of(null, 0));
    }
}
