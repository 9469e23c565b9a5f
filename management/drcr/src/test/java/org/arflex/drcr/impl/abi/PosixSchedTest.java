package org.arflex.drcr.impl.abi;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertFalse;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.file.Files;
import java.nio.file.Path;
import java.util.concurrent.atomic.AtomicReference;
import org.junit.jupiter.api.Test;

/** The heartbeat thread's SCHED_FIFO switch, checked in /proc for the thread itself. */
class PosixSchedTest {

    /** Fields 40 (rt_priority) and 41 (policy) of /proc/thread-self/stat, after the comm field. */
    private static String[] policyAndPriority() throws Exception {
        String stat = Files.readString(Path.of("/proc/thread-self/stat"));
        String[] f = stat.substring(stat.lastIndexOf(')') + 2).split(" ");
        return new String[] {f[41 - 3], f[40 - 3]};
    }

    /** CAP_SYS_NICE (bit 23) in this process's effective capabilities (/proc/self/status CapEff). */
    static boolean mayUseRealtime() throws Exception {
        for (String line : Files.readAllLines(Path.of("/proc/self/status"))) {
            if (line.startsWith("CapEff:")) {
                return (Long.parseUnsignedLong(line.substring(7).strip(), 16) & (1L << 23)) != 0;
            }
        }
        throw new AssertionError("no CapEff line in /proc/self/status");
    }

    @Test
    void aThreadSwitchesItselfToFifoOrSaysWhyNot() throws Exception {
        AtomicReference<Object> result = new AtomicReference<>();
        Thread t = new Thread(() -> {
            try {
                String why = Posix.fifoThisThread(1);
                result.set(why != null ? why : policyAndPriority());
            } catch (Exception e) {
                result.set(e);
            }
        });
        t.start();
        t.join(10_000);
        Object r = result.get();
        if (r instanceof String why) {
            // a refusal is right only where the process may not (no CAP_SYS_NICE: not root); where
            // it may, a refusal is the finding (D82: it once passed as "not permitted here")
            assertTrue(why.startsWith("errno "), why);
            assertFalse(mayUseRealtime(), "SCHED_FIFO refused with CAP_SYS_NICE in effect: " + why);
            return;
        }
        assertTrue(r instanceof String[], String.valueOf(r));
        String[] pp = (String[]) r;
        assertEquals("1", pp[0], "policy SCHED_FIFO");
        assertEquals("1", pp[1], "rt priority");
        // the calling (test) thread is untouched
        assertEquals("0", policyAndPriority()[0]);
    }
}
