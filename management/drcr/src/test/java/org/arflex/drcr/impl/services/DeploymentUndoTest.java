package org.arflex.drcr.impl.services;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.lang.reflect.Proxy;
import java.util.ArrayList;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import java.util.function.Function;
import org.arflex.drcr.ChangeSetService;
import org.arflex.drcr.dto.ChangeSetDTO;
import org.junit.jupiter.api.Test;
import org.osgi.framework.Bundle;
import org.osgi.framework.BundleException;

/**
 * Taking a deployment set back (D50) with doubles: a change-set service that answers as the DRCR's
 * does, and bundles that record their uninstall. A set applied whose update was rolled back after
 * its switch is taken back by one change set (its new components uninstalled, its uninstalled
 * ones installed again, the old values written back) and only then are its bundles uninstalled;
 * a take-back the cell refuses leaves the bundles, says so, and uninstalls nothing.
 */
class DeploymentUndoTest {

    static final String ROLLED_BACK = "update tcp-correction: rolled back after 41 cycles of the new version "
            + "(file:/srv/sets/tc-1.0.1.jar): the new half exited (SIGSEGV); pid 4711 (tcp-correction) runs it again "
            + "(its consumers bound back 1.2 ms after the cause was seen)";

    private final List<String> events = new ArrayList<>();
    private final List<List<String>> applied = new ArrayList<>();

    private ChangeSetService service(Function<List<String>, ChangeSetDTO> apply) {
        return (ChangeSetService) Proxy.newProxyInstance(getClass().getClassLoader(), new Class<?>[] {ChangeSetService.class},
                (p, m, a) -> {
                    if (m.getName().equals("apply")) {
                        @SuppressWarnings("unchecked")
                        List<String> actions = (List<String>) a[0];
                        applied.add(List.copyOf(actions));
                        events.add("apply " + String.join("; ", actions));
                        return apply.apply(actions);
                    }
                    throw new UnsupportedOperationException(m.getName());
                });
    }

    private Bundle bundle(long id, String location, boolean fails) {
        return (Bundle) Proxy.newProxyInstance(getClass().getClassLoader(), new Class<?>[] {Bundle.class}, (p, m, a) ->
                switch (m.getName()) {
                    case "getBundleId" -> id;
                    case "getLocation" -> location;
                    case "uninstall" -> {
                        if (fails) {
                            throw new BundleException("bundle " + id + " is locked");
                        }
                        events.add("uninstall bundle " + id);
                        yield null;
                    }
                    case "hashCode" -> (int) id;
                    case "equals" -> p == a[0];
                    default -> throw new UnsupportedOperationException(m.getName());
                });
    }

    private static ChangeSetDTO outcome(boolean applied, String refusal, String text) {
        ChangeSetDTO d = new ChangeSetDTO();
        d.applied = applied;
        d.admitted = refusal == null;
        d.refusal = refusal;
        d.text = text;
        return d;
    }

    private DeploymentUndo.Done done(boolean lockedBundle) {
        Map<String, String> old = new LinkedHashMap<>();
        old.put("sim-robot speed", "0.8");
        return new DeploymentUndo.Done(List.of(bundle(34, "file:/srv/sets/tool-gripper.jar", lockedBundle)),
                List.of("tool-gripper"), List.of("teach"), List.of("tcp-correction"), old);
    }

    @Test
    void onlyARollbackOrANewVersionThatDidNotStartOfTheSetsOwnUpdatesCount() {
        assertEquals(List.of("update tcp-correction rolled back after the switch"), DeploymentUndo.notHeld(
                "applied: ...\n" + ROLLED_BACK + "\n", List.of("tcp-correction", "vision")));
        assertEquals(List.of("update tcp-correction did not start at the switch"), DeploymentUndo.notHeld(
                "update tcp-correction: the new version did not start\n", List.of("tcp-correction")));
        assertEquals(List.of(), DeploymentUndo.notHeld("update tcp-correction: committed: the new version ran 300 "
                + "cycles (0 cycles late, the old one 0)\n", List.of("tcp-correction")));
        assertEquals(List.of(), DeploymentUndo.notHeld("warning: no verdict of the rollback window yet: timeout\n",
                List.of("tcp-correction")), "no verdict: nothing is taken back on a guess");
        assertEquals(List.of(), DeploymentUndo.notHeld(ROLLED_BACK, List.of("tcp")), "another component's name");
        assertEquals(List.of(), DeploymentUndo.notHeld(null, List.of("tcp-correction")));
    }

    @Test
    void aSetRolledBackAfterItsSwitchIsTakenBackThenItsBundlesUninstalled() {
        DeploymentUndo undo = new DeploymentUndo(service(a -> outcome(true, null, "change set: ...\napplied: ...\n")),
                events::add);
        StringBuilder text = new StringBuilder();
        String why = undo.takeBack("file:/srv/sets/s.xml", text, done(false),
                List.of("update tcp-correction rolled back after the switch"));
        assertEquals(List.of(List.of("uninstall tool-gripper", "install teach", "set sim-robot speed 0.8")), applied);
        assertEquals(List.of("apply uninstall tool-gripper; install teach; set sim-robot speed 0.8", "uninstall bundle 34"),
                events, "the components out of the cell before their bundle leaves Felix");
        assertEquals("update tcp-correction rolled back after the switch; the set was taken back", why);
        assertTrue(text.toString().startsWith("taking the set back (update tcp-correction rolled back after the switch): "
                + "uninstall tool-gripper; install teach; set sim-robot speed 0.8\nchange set: ...\n"), text::toString);
        assertTrue(text.toString().endsWith("uninstalled again: bundle 34 (file:/srv/sets/tool-gripper.jar)\n"), text::toString);
    }

    @Test
    void aTakeBackTheCellRefusesLeavesTheBundlesAndSaysWhy() {
        DeploymentUndo undo = new DeploymentUndo(service(a -> outcome(false, "the set would stop 'trajectory' (input "
                + "'tool' of 'trajectory': no provider)", "refused: ...\n")), events::add);
        StringBuilder text = new StringBuilder();
        String why = undo.takeBack("file:/srv/sets/s.xml", text, done(false),
                List.of("update tcp-correction rolled back after the switch"));
        assertEquals(1, applied.size());
        assertTrue(events.stream().noneMatch(e -> e.startsWith("uninstall bundle")), events::toString);
        assertEquals("update tcp-correction rolled back after the switch; taking it back was refused (the set would stop "
                + "'trajectory' (input 'tool' of 'trajectory': no provider))", why);
        assertTrue(text.toString().contains("warning: deployment set file:/srv/sets/s.xml: could not be taken back: the set "
                + "would stop 'trajectory'"), text::toString);
        assertTrue(events.stream().anyMatch(e -> e.startsWith("arflex: deployment set file:/srv/sets/s.xml: could not be "
                + "taken back")), "logged: " + events);
    }

    @Test
    void aSetWithNothingOfItsOwnToTakeBackAppliesNoChangeSet() {
        DeploymentUndo undo = new DeploymentUndo(service(a -> {
            throw new AssertionError("no change set expected");
        }), events::add);
        String why = undo.takeBack("u", new StringBuilder(), new DeploymentUndo.Done(List.of(), List.of(), List.of(),
                List.of("tcp-correction"), Map.of()), List.of("update tcp-correction rolled back after the switch"));
        assertEquals("update tcp-correction rolled back after the switch; the set had nothing else to take back", why);
        assertEquals(List.of(), applied);
    }

    @Test
    void aBundleThatCannotBeUninstalledIsNamedAndTheOthersStillGo() {
        DeploymentUndo undo = new DeploymentUndo(service(a -> outcome(true, null, "")), events::add);
        StringBuilder text = new StringBuilder();
        undo.uninstall("u", text, List.of(bundle(34, "file:/a.jar", true), bundle(35, "file:/b.jar", false)));
        assertEquals("warning: deployment set u: bundle 34 could not be uninstalled again: bundle 34 is locked\n"
                + "uninstalled again: bundle 35 (file:/b.jar)\n", text.toString());
    }
}
