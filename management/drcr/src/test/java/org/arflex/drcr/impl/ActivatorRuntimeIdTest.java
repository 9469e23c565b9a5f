package org.arflex.drcr.impl;

import static org.junit.jupiter.api.Assertions.assertNotEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import org.junit.jupiter.api.Test;

/** The default runtime id is unpredictable (issue 16 finding 6, DECISIONS.md D13). */
class ActivatorRuntimeIdTest {

    @Test
    void defaultIdIsPidAndTenRandomHexDigits() {
        long pid = ProcessHandle.current().pid();
        String a = Activator.defaultRuntimeId(pid);
        String b = Activator.defaultRuntimeId(pid);
        assertTrue(a.matches("rt" + pid + "-[0-9a-f]{10}"), a);
        assertTrue(a.matches("[a-z0-9-]{1,40}"), a);
        assertTrue(Activator.defaultRuntimeId(Integer.MAX_VALUE).length() <= 40);
        assertNotEquals(a, b, "two runtimes of the same pid get different ids");
    }
}
