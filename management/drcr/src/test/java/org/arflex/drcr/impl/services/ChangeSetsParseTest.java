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
    void anUnknownOrIncompleteActionIsRefusedNamingIt() {
        assertEquals("unknown action 'update' (actions: install <component>, uninstall <component>, set <component> "
                + "<parameter> <value>)", assertThrows(IllegalArgumentException.class,
                        () -> ChangeSets.parse(List.of("update", "vision"))).getMessage());
        assertEquals("'set teach mass' is incomplete (set <component> <parameter> <value>)",
                assertThrows(IllegalArgumentException.class,
                        () -> ChangeSets.parse(List.of("install", "teach", "set", "teach", "mass"))).getMessage());
    }
}
