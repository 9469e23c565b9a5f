package org.arflex.drcr.impl.services;

import static org.junit.jupiter.api.Assertions.assertArrayEquals;
import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertNull;

import java.util.List;
import java.util.concurrent.atomic.AtomicLong;
import org.arflex.drcr.dto.ChangeSetDTO;
import org.junit.jupiter.api.Test;

/** The history of applied sets (D46): newest first, bounded, stamped, and what it keeps cannot be changed from outside. */
class ChangeSetHistoryTest {

    private static ChangeSetDTO set(String action, String refusal) {
        ChangeSetDTO d = new ChangeSetDTO();
        d.actions = new String[] {action};
        d.refusal = refusal;
        d.applied = refusal == null;
        d.admitted = refusal == null;
        d.text = "change set: " + action + "\n";
        return d;
    }

    @Test
    void keepsTheNewestFiftyNewestFirstEachWithItsTime() {
        AtomicLong now = new AtomicLong(1_000);
        ChangeSetHistory h = new ChangeSetHistory(now::get);
        for (int i = 0; i < ChangeSetHistory.MAX + 7; i++) {
            now.set(1_000 + i);
            ChangeSetDTO back = h.record(set("install c" + i, i % 2 == 0 ? null : "refused " + i));
            assertEquals(1_000 + i, back.finishedMillis, "the caller's outcome carries its time too");
        }
        List<ChangeSetDTO> l = h.list();
        assertEquals(ChangeSetHistory.MAX, l.size());
        int newest = ChangeSetHistory.MAX + 6;
        assertArrayEquals(new String[] {"install c" + newest}, l.get(0).actions);
        assertEquals(1_000 + newest, l.get(0).finishedMillis);
        assertEquals("install c7", l.get(l.size() - 1).actions[0], "the seven oldest were dropped");
        assertEquals("refused 7", l.get(l.size() - 1).refusal);
        assertNull(l.get(0).refusal, "the newest (56, applied)");
        assertEquals("refused 55", l.get(1).refusal);
    }

    @Test
    void whatItKeepsIsACopy() {
        ChangeSetHistory h = new ChangeSetHistory(() -> 5);
        ChangeSetDTO d = set("uninstall a", null);
        h.record(d);
        d.actions[0] = "changed by the caller";
        d.refusal = "changed";
        h.list().get(0).actions[0] = "changed by a reader";
        ChangeSetDTO kept = h.list().get(0);
        assertEquals("uninstall a", kept.actions[0]);
        assertNull(kept.refusal);
    }
}
