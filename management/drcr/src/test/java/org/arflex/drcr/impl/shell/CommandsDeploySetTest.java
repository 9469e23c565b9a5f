package org.arflex.drcr.impl.shell;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.ArrayList;
import java.util.List;
import java.util.Optional;
import org.arflex.drcr.ChangeSetService;
import org.arflex.drcr.dto.ChangeSetDTO;
import org.junit.jupiter.api.Test;

/** {@code arflex:deploy set <url> [plan]} (D45) beside {@code deploy <url> [<sha256>]}. */
class CommandsDeploySetTest {

    private final List<String> calls = new ArrayList<>();

    private final ChangeSetService sets = new ChangeSetService() {
        @Override
        public ChangeSetDTO plan(List<String> actions) {
            throw new AssertionError("not a change set");
        }

        @Override
        public ChangeSetDTO apply(List<String> actions) {
            throw new AssertionError("not a change set");
        }

        @Override
        public ChangeSetDTO deploy(String url, boolean apply) {
            calls.add((apply ? "apply " : "plan ") + url);
            ChangeSetDTO d = new ChangeSetDTO();
            d.text = "deployment set from " + url + "\n" + (url.contains("bad") ? "refused: a jar\n" : "applied\n");
            d.refusal = url.contains("bad") ? "a jar" : null;
            return d;
        }

        @Override
        public List<ChangeSetDTO> history() {
            throw new AssertionError("not a change set");
        }

        @Override
        public org.arflex.drcr.dto.ChangeSetProgressDTO progress() {
            throw new AssertionError("not a change set");
        }
    };

    private final Commands cmd = new Commands(null, null, null, n -> Optional.empty(), new Commands.BundleUpdater() {
        @Override
        public String update(long id, String location, String sha256) {
            throw new AssertionError("no update");
        }

        @Override
        public String deploy(String location, String sha256) {
            calls.add("deploy " + location + " " + sha256);
            return "Bundle ID: 9";
        }
    }, (c, p) -> null, new CellWatch(), sets);

    @Test
    void setAppliesAndSetPlanIsTheDryRun() {
        assertEquals("deployment set from https://h/s.xml\napplied", cmd.deploy("set", "https://h/s.xml"));
        assertEquals("deployment set from file:/s.xml\napplied", cmd.deploy("set", "file:/s.xml", "plan"));
        assertEquals("error: deployment set from file:/bad.xml\nrefused: a jar", cmd.deploy("set", "file:/bad.xml"));
        assertEquals(List.of("apply https://h/s.xml", "plan file:/s.xml", "apply file:/bad.xml"), calls);
    }

    @Test
    void aJarDeployIsUnchangedAndAnythingElseIsTheUsage() {
        assertEquals("Bundle ID: 9", cmd.deploy("https://h/x.jar", "ab12"));
        assertEquals(List.of("deploy https://h/x.jar ab12"), calls);
        String usage = cmd.deploy("set", "file:/s.xml", "apply");
        assertTrue(usage.startsWith("usage: deploy <https-or-file-url> [<sha256>]")
                && usage.contains("deploy set <descriptor https-or-file-url> [plan]"), usage);
        assertTrue(cmd.deploy("set").startsWith("usage:"));
        assertEquals(List.of("deploy https://h/x.jar ab12"), calls, "nothing called for a usage");
    }
}
