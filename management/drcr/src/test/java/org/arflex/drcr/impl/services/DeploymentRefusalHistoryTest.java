package org.arflex.drcr.impl.services;

import static org.junit.jupiter.api.Assertions.assertArrayEquals;
import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.file.Files;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import org.arflex.drcr.dto.ChangeSetDTO;
import org.junit.jupiter.api.Test;
import org.junit.jupiter.api.io.TempDir;

/**
 * A deployment set refused before its change set (D50) is in the change-set history, with its
 * reason, as the console's Change sets page lists it; a dry run is not (as a change set's plan
 * is not). The refusals here come before the cell is asked, so no cell is needed.
 */
class DeploymentRefusalHistoryTest {

    @TempDir
    Path dir;

    private final List<String> log = new ArrayList<>();
    private final ChangeSetHistory history = new ChangeSetHistory(() -> 1_764_000_000_000L);
    private final DeploymentSets sets = new DeploymentSets(null, null, null, null, null, null, null, log::add);

    DeploymentRefusalHistoryTest() {
        sets.recordInto(history);
    }

    @Test
    void aDescriptorErrorIsRecordedWithItsLineAndADryRunIsNot() throws Exception {
        Path bad = Files.writeString(dir.resolve("bad.xml"), "<deployment xmlns=\"urn:arflex:deployment:1\">\n"
                + "  <uninstall component=\"teach\" jar=\"x.jar\"/>\n</deployment>\n");
        String url = bad.toUri().toString();
        ChangeSetDTO plan = sets.deploy(url, false);
        assertTrue(plan.refusal != null && plan.refusal.startsWith("descriptor: "), plan.text);
        assertEquals(List.of(), history.list(), "a dry run changes nothing and is not an outcome");

        ChangeSetDTO d = sets.deploy(url, true);
        List<ChangeSetDTO> h = history.list();
        assertEquals(1, h.size());
        ChangeSetDTO e = h.get(0);
        assertArrayEquals(new String[] {"deploy " + url}, e.actions);
        assertFalse(e.applied);
        assertFalse(e.admitted);
        assertTrue(e.refusal.matches("descriptor: " + java.util.regex.Pattern.quote(url)
                + ":2:\\d+: <uninstall>: unknown attribute 'jar' \\(allowed: component\\)"), e.refusal);
        assertEquals(d.refusal, e.refusal);
        assertTrue(e.text.contains("refused: " + e.refusal), e.text);
        assertEquals(1_764_000_000_000L, e.finishedMillis);
    }

    @Test
    void anUnreadableDescriptorIsRecordedNewestFirst() {
        String first = dir.resolve("missing-1.xml").toUri().toString();
        String second = dir.resolve("missing-2.xml").toUri().toString();
        sets.deploy(first, true);
        sets.deploy(second, true);
        List<ChangeSetDTO> h = history.list();
        assertEquals(2, h.size());
        assertTrue(h.get(0).refusal.startsWith("cannot read the descriptor " + second + ": "), h.get(0).refusal);
        assertTrue(h.get(1).refusal.startsWith("cannot read the descriptor " + first + ": "), h.get(1).refusal);
    }
}
