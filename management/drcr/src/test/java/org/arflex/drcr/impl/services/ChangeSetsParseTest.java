package org.arflex.drcr.impl.services;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertThrows;

import java.util.List;
import org.junit.jupiter.api.Test;

/** The actions of {@code arflex:change}: one token list (Gogo's arguments) or one string per action. */
class ChangeSetsParseTest {

    private static List<String> flat(List<String> actions) {
        return ChangeSets.parse(actions).stream().map(a -> String.join(" ", a)).toList();
    }

    @Test
    void tokensOrActionsGiveTheSameSteps() {
        List<String> want = List.of("install teach", "uninstall trajectory", "set teach mass 30");
        assertEquals(want, flat(List.of("install", "teach", "uninstall", "trajectory", "set", "teach", "mass", "30")));
        assertEquals(want, flat(List.of("install teach", "uninstall trajectory", "set teach mass 30")));
        assertEquals(want, flat(List.of("install teach; uninstall trajectory; set teach mass 30")));
    }

    @Test
    void theActionsAreRecordedOneTextPerActionWhicheverWayTheyCame() {
        String sha = "ab".repeat(32);
        List<String> want = List.of("install teach", "update tcp-correction file:/x.jar " + sha
                + " window 300 shadow 500 tolerance corrected.q 1e-6 envelope error.value 0 5", "set teach mass 30",
                "update c file:/c.jar");
        assertEquals(want, ChangeSetActions.normalized(List.of("install", "teach", "update", "tcp-correction", "file:/x.jar",
                sha, "shadow", "500", "window", "300", "tolerance", "corrected.q", "1e-6", "envelope", "error.value", "0",
                "5", "set", "teach", "mass", "30", "update", "c", "file:/c.jar")));
        assertEquals(want, ChangeSetActions.normalized(List.of("install teach", "update tcp-correction file:/x.jar " + sha
                + " window 300 shadow 500 tolerance corrected.q 1e-6 envelope error.value 0 5", "set teach mass 30; update c file:/c.jar")));
        // the normal form parses to the same steps
        assertEquals(flat(want), flat(ChangeSetActions.normalized(want)));
        // what does not parse is kept as given, for its refusal to name
        assertEquals(List.of("frobnicate", "x"), ChangeSetActions.normalized(List.of("frobnicate", "x")));
    }

    @Test
    void anUpdateTakesItsJarThenAnOptionalPinAndWindow() {
        String sha = "ab".repeat(32);
        assertEquals(List.of("update tcp-correction file:/x.jar   ", "uninstall b"),
                flat(List.of("update", "tcp-correction", "file:/x.jar", "uninstall", "b")));
        assertEquals(List.of("update tcp-correction file:/x.jar " + sha + " 2000 ", "set a gain 2"),
                flat(List.of("update tcp-correction file:/x.jar " + sha + " window 2000; set a gain 2")));
        assertEquals(List.of("update c https://h/c.jar  50 "), flat(List.of("update", "c", "https://h/c.jar", "window", "50")));
        assertEquals(List.of("update c file:/c.jar    envelope corrected.q -3.2 3.2 envelope error.value 0 5", "uninstall d"),
                flat(List.of("update c file:/c.jar envelope corrected.q -3.2 3.2 envelope error.value 0 5 uninstall d")));
        assertEquals("update c: envelope corrected.q: 1 0 is not a range (<min> <max>)",
                assertThrows(IllegalArgumentException.class,
                        () -> ChangeSets.parse(List.of("update c file:/c.jar envelope corrected.q 1 0"))).getMessage());
    }

    @Test
    void anUpdateTakesAShadowRunAndTolerances() {
        assertEquals(List.of("update c file:/c.jar  100 200 tolerance corrected.q 0.001 envelope corrected.q -3 3",
                        "uninstall d"),
                flat(List.of("update c file:/c.jar window 100 shadow 200 tolerance corrected.q 0.001 envelope corrected.q "
                        + "-3 3 uninstall d")));
        assertEquals(List.of("update c file:/c.jar   50 tolerance error.value 0"),
                flat(List.of("update", "c", "file:/c.jar", "shadow", "50", "tolerance", "error.value", "0")));
        assertEquals("update c: shadow needs a number of cycles", assertThrows(IllegalArgumentException.class,
                () -> ChangeSets.parse(List.of("update c file:/c.jar shadow many"))).getMessage());
        assertEquals("update c: tolerance corrected.q: -0.1 is not a tolerance (a finite number >= 0)",
                assertThrows(IllegalArgumentException.class,
                        () -> ChangeSets.parse(List.of("update c file:/c.jar shadow 10 tolerance corrected.q -0.1"))).getMessage());
        assertEquals("update c: tolerance corrected.q: wide is not a tolerance (a finite number >= 0)",
                assertThrows(IllegalArgumentException.class,
                        () -> ChangeSets.parse(List.of("update c file:/c.jar tolerance corrected.q wide"))).getMessage());
        assertEquals("update c: tolerance needs <port>.<field> <max difference>", assertThrows(IllegalArgumentException.class,
                () -> ChangeSets.parse(List.of("update c file:/c.jar tolerance corrected 0.1"))).getMessage());
    }

    @Test
    void anUnknownOrIncompleteActionIsRefusedNamingIt() {
        assertEquals("unknown action 'upgrade' (actions: install <component>, uninstall <component>, set <component> "
                + "<parameter> <value>, update <component> <jar URL> [<sha256>] [window <cycles>] [shadow <cycles>] [envelope "
                + "<port>.<field> <min> <max>]... [tolerance <port>.<field> <max difference>]...)",
                assertThrows(IllegalArgumentException.class, () -> ChangeSets.parse(List.of("upgrade", "vision"))).getMessage());
        assertEquals("'update vision' is incomplete (update <component> <jar URL> [<sha256>] [window <cycles>] "
                + "[shadow <cycles>] [envelope <port>.<field> <min> <max>]... [tolerance <port>.<field> <max difference>]...)",
                assertThrows(IllegalArgumentException.class, () -> ChangeSets.parse(List.of("update", "vision"))).getMessage());
        assertEquals("update vision: window needs a number of cycles", assertThrows(IllegalArgumentException.class,
                () -> ChangeSets.parse(List.of("update vision file:/v.jar window soon"))).getMessage());
        assertEquals("'set teach mass' is incomplete (set <component> <parameter> <value>)",
                assertThrows(IllegalArgumentException.class,
                        () -> ChangeSets.parse(List.of("install", "teach", "set", "teach", "mass"))).getMessage());
    }
}
