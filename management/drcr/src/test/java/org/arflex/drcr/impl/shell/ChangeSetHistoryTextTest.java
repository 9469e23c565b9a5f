package org.arflex.drcr.impl.shell;

import static org.junit.jupiter.api.Assertions.assertEquals;

import java.util.List;
import java.util.Optional;
import org.arflex.drcr.ChangeSetService;
import org.arflex.drcr.dto.ChangeSetDTO;
import org.arflex.drcr.dto.ChangeSetProgressDTO;
import org.arflex.drcr.dto.UpdateProgressDTO;
import org.junit.jupiter.api.Test;

/**
 * {@code arflex:change history} (D62): each set applied, newest first, with its outcome and a
 * line per update as the live progress last showed it (a cancelled one naming the update whose
 * rejection cancelled it); a count; none; a bad count.
 */
class ChangeSetHistoryTextTest {

    private static UpdateProgressDTO entry(String component, String phase, long cycle, long cycles, String worstField,
                                           String verdict, String why) {
        UpdateProgressDTO u = new UpdateProgressDTO();
        u.component = component;
        u.phase = phase;
        u.cycle = cycle;
        u.cycles = cycles;
        u.worstField = worstField;
        u.worstDeviation = worstField == null ? 0 : 0.002;
        u.tolerance = worstField == null ? 0 : 0.01;
        u.verdict = verdict;
        u.why = why;
        return u;
    }

    private static List<ChangeSetDTO> history() {
        ChangeSetDTO rejected = new ChangeSetDTO();
        rejected.actions = new String[] {"update src file:/s.jar", "update stage file:/x.jar"};
        rejected.outcome = "rejected-in-shadow";
        rejected.refusal = "update stage: rejected in shadow after 45 cycles: it exited; nothing changed (pid 9 runs "
                + "stage on)";
        rejected.finishedMillis = 1_764_189_663_000L; // 2025-11-26 20:41:03 UTC
        rejected.updates = new UpdateProgressDTO[] {
                entry("src", "shadow", 25, 100, "y.value", "cancelled",
                        "cancelled: update stage was rejected in shadow (it exited)"),
                entry("stage", "shadow", 45, 200, null, "rejected-in-shadow", rejected.refusal)};
        ChangeSetDTO committed = new ChangeSetDTO();
        committed.actions = new String[] {"update stage file:/x.jar window 50"};
        committed.outcome = "committed";
        committed.applied = true;
        committed.admitted = true;
        committed.prepareMs = 12.34;
        committed.switchUs = 456.7;
        committed.finishedMillis = 1_764_189_600_000L;
        committed.updates = new UpdateProgressDTO[] {entry("stage", "window", 50, 50, null, "committed", "update stage: "
                + "committed: ...")};
        ChangeSetDTO refused = new ChangeSetDTO();
        refused.actions = new String[] {"uninstall nobody"};
        refused.refusal = "uninstall nobody: no such component";
        refused.finishedMillis = 1_764_189_500_000L;
        return List.of(rejected, committed, refused);
    }

    @Test
    void eachSetNewestFirstWithItsOutcomeAndALinePerUpdate() {
        assertEquals("3 of the 3 change sets applied in this runtime, newest first\n"
                + "2025-11-26 20:41:03 UTC  change set: update src file:/s.jar; update stage file:/x.jar\n"
                + "  outcome: rejected-in-shadow: update stage: rejected in shadow after 45 cycles: it exited; nothing "
                + "changed (pid 9 runs stage on)\n"
                + "  update src: shadow run, cycle 25 of 100, worst deviation in shadow y.value 0.00200 (tolerance 0.01);"
                + " cancelled: update stage was rejected in shadow (it exited)\n"
                + "  update stage: shadow run, cycle 45 of 200; rejected-in-shadow\n"
                + "2025-11-26 20:40:00 UTC  change set: update stage file:/x.jar window 50\n"
                + "  outcome: committed\n"
                + "  update stage: rollback window, cycle 50 of 50; committed\n"
                + "  prepared in 12.3 ms, switch turn 0.457 ms\n"
                + "2025-11-26 20:38:20 UTC  change set: uninstall nobody\n"
                + "  outcome: refused: uninstall nobody: no such component", ChangeSetHistoryText.of(history(), 50));
    }

    @Test
    void throughTheCommandACountANoneAndABadCount() {
        List<ChangeSetDTO>[] kept = new List[] {history()};
        ChangeSetService sets = new ChangeSetService() {
            @Override
            public ChangeSetDTO plan(List<String> actions) {
                throw new AssertionError();
            }

            @Override
            public ChangeSetDTO apply(List<String> actions) {
                throw new AssertionError();
            }

            @Override
            public ChangeSetDTO deploy(String url, boolean apply) {
                throw new AssertionError();
            }

            @Override
            public List<ChangeSetDTO> history() {
                return kept[0];
            }

            @Override
            public ChangeSetProgressDTO progress() {
                throw new AssertionError();
            }
        };
        Commands cmd = new Commands(null, null, null, n -> Optional.empty(), null, (c, p) -> null, new CellWatch(), sets);
        assertEquals(ChangeSetHistoryText.of(history(), 50), cmd.change("history"));
        assertEquals("1 of the 3 change sets applied in this runtime, newest first", cmd.change("history", "1").lines()
                .findFirst().orElseThrow());
        assertEquals(5, cmd.change("history", "1").lines().count());
        assertEquals("error: change history: '0' is not a count of sets (1 to 999)", cmd.change("history", "0"));
        assertEquals("error: change history: 'all' is not a count of sets (1 to 999)", cmd.change("history", "all"));
        kept[0] = List.of();
        assertEquals("no change set in the history (the newest 50 are kept in the DRCR's data area, across restarts)",
                cmd.change("history"));
    }
}
