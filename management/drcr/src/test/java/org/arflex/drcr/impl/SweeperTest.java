package org.arflex.drcr.impl;

import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertTrue;

import org.junit.jupiter.api.Test;

/** Which runtime ids the Sweeper takes for a dead runtime's. */
class SweeperTest {

    /** A pid that is not running: beyond pid_max. */
    private static final long DEAD = 99_999_999L;

    @Test
    void defaultIdsOfDeadRuntimesAreStaleInBothForms() {
        String own = Activator.defaultRuntimeId(ProcessHandle.current().pid());
        assertTrue(Sweeper.stale("rt" + DEAD, own), "old form rt<pid>");
        assertTrue(Sweeper.stale("rt" + DEAD + "-0123456789", own), "new form rt<pid>-<10 hex>");
        assertTrue(Sweeper.stale(own, own), "our own id");
    }

    @Test
    void idsOfLiveRuntimesAndOtherIdsAreNot() {
        String own = "rt1-aaaaaaaaaa";
        long live = ProcessHandle.current().pid();
        assertFalse(Sweeper.stale("rt" + live, own));
        assertFalse(Sweeper.stale("rt" + live + "-0123456789", own));
        assertFalse(Sweeper.stale("rt" + DEAD + "-012345678", own), "9 hex digits: not a default id");
        assertFalse(Sweeper.stale("rt" + DEAD + "-0123456789x", own));
        assertFalse(Sweeper.stale("cell" + DEAD, own), "configured ids are never swept by pid");
    }
}
