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
    void anUpdateTakesItsJarThenAnOptionalPinAndWindow() {
        String sha = "ab".repeat(32);
        assertEquals(List.of("update tcp-correction file:/x.jar  ", "uninstall b"),
                flat(List.of("update", "tcp-correction", "file:/x.jar", "uninstall", "b")));
        assertEquals(List.of("update tcp-correction file:/x.jar " + sha + " 2000", "set a gain 2"),
                flat(List.of("update tcp-correction file:/x.jar " + sha + " window 2000; set a gain 2")));
        assertEquals(List.of("update c https://h/c.jar  50"), flat(List.of("update", "c", "https://h/c.jar", "window", "50")));
        assertEquals(List.of("update c file:/c.jar   corrected.q -3.2 3.2 error.value 0 5", "uninstall d"),
                flat(List.of("update c file:/c.jar envelope corrected.q -3.2 3.2 envelope error.value 0 5 uninstall d")));
        assertEquals("update c: envelope corrected.q: 1 0 is not a range (<min> <max>)",
                assertThrows(IllegalArgumentException.class,
                        () -> ChangeSets.parse(List.of("update c file:/c.jar envelope corrected.q 1 0"))).getMessage());
    }

    @Test
    void anUnknownOrIncompleteActionIsRefusedNamingIt() {
        assertEquals("unknown action 'upgrade' (actions: install <component>, uninstall <component>, set <component> "
                + "<parameter> <value>, update <component> <jar URL> [<sha256>] [window <cycles>] [envelope <port>.<field> <min> "
                + "<max>]...)",
                assertThrows(IllegalArgumentException.class, () -> ChangeSets.parse(List.of("upgrade", "vision"))).getMessage());
        assertEquals("'update vision' is incomplete (update <component> <jar URL> [<sha256>] [window <cycles>] "
                + "[envelope <port>.<field> <min> <max>]...)",
                assertThrows(IllegalArgumentException.class, () -> ChangeSets.parse(List.of("update", "vision"))).getMessage());
        assertEquals("update vision: window needs a number of cycles", assertThrows(IllegalArgumentException.class,
                () -> ChangeSets.parse(List.of("update vision file:/v.jar window soon"))).getMessage());
        assertEquals("'set teach mass' is incomplete (set <component> <parameter> <value>)",
                assertThrows(IllegalArgumentException.class,
                        () -> ChangeSets.parse(List.of("install", "teach", "set", "teach", "mass"))).getMessage());
    }
}
