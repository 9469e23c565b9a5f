package org.arflex.drcr.impl.abi;

import static org.junit.jupiter.api.Assertions.assertEquals;
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
        if (r instanceof String why) {  // not permitted here (not root, no CAP_SYS_NICE)
            assertTrue(why.startsWith("errno "), why);
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
