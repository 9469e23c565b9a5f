package org.arflex.drcr.impl.supervisor;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertTrue;

import org.arflex.contract.FaultPolicy;
import org.arflex.contract.FaultPolicy.Restart;
import org.arflex.contract.FaultPolicy.SafeOutput;
import org.junit.jupiter.api.Test;

class RestartPolicyTest {

    private long now;

    private RestartPolicy policy(Restart r, int intensity, long window, long backoff) {
        return new RestartPolicy(new FaultPolicy(r, intensity, window, backoff, SafeOutput.HOLD, 500), () -> now);
    }

    @Test
    void permanentBacksOffExponentiallyThenGivesUp() {
        RestartPolicy p = policy(Restart.PERMANENT, 3, 10_000, 100);
        assertEquals(3, p.restartsLeft());
        RestartPolicy.Decision d1 = p.onExit(true, "killed by signal 9");
        assertTrue(d1.restart());
        assertEquals(100, d1.delayMs());
        now += 200;
        assertEquals(200, p.onExit(true, "x").delayMs());
        now += 300;
        assertEquals(400, p.onExit(true, "x").delayMs());
        assertEquals(0, p.restartsLeft());
        now += 500;
        RestartPolicy.Decision last = p.onExit(true, "exit status 3");
        assertFalse(last.restart());
        assertTrue(last.reason().contains("restart intensity exceeded"), last.reason());
        assertTrue(last.reason().contains("exit status 3"), last.reason());
    }

    @Test
    void windowSlidesSoSparseCrashesAlwaysRestart() {
        RestartPolicy p = policy(Restart.PERMANENT, 2, 1_000, 50);
        for (int i = 0; i < 10; i++) {
            RestartPolicy.Decision d = p.onExit(true, "crash " + i);
            assertTrue(d.restart(), d.reason());
            assertEquals(50, d.delayMs());
            now += 1_000;
        }
        assertEquals(10, p.total());
    }

    @Test
    void transientRestartsOnlyAbnormalExits() {
        RestartPolicy p = policy(Restart.TRANSIENT, 5, 1_000, 10);
        assertFalse(p.onExit(false, "exit status 0").restart());
        assertTrue(p.onExit(true, "exit status 1").restart());
    }

    @Test
    void temporaryNeverRestarts() {
        RestartPolicy p = policy(Restart.TEMPORARY, 5, 1_000, 10);
        RestartPolicy.Decision d = p.onExit(true, "crash");
        assertFalse(d.restart());
        assertTrue(d.reason().contains("temporary"));
        assertEquals(0, p.restartsLeft());
    }

    @Test
    void backoffIsCapped() {
        RestartPolicy p = policy(Restart.PERMANENT, 100, 1_000_000, 1_000);
        long last = 0;
        for (int i = 0; i < 20; i++) {
            last = p.onExit(true, "x").delayMs();
        }
        assertEquals(RestartPolicy.MAX_BACKOFF_MS, last);
    }

    @Test
    void resetForgetsHistory() {
        RestartPolicy p = policy(Restart.PERMANENT, 1, 10_000, 10);
        assertTrue(p.onExit(true, "x").restart());
        assertFalse(p.onExit(true, "x").restart());
        p.reset();
        assertTrue(p.onExit(true, "x").restart());
    }
}
