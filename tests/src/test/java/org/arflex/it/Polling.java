package org.arflex.it;

import static org.junit.jupiter.api.Assertions.fail;

import java.util.function.Supplier;

/**
 * A wait on a condition with a deadline (no sleep stands for a wait): polls every 2 ms at first,
 * doubled up to 50 ms, so what is quick is seen quickly and a long wait costs the polled side
 * little. It returns only when the condition held; a timeout fails with {@code onTimeout}'s
 * account, and an interrupt fails too, with the thread's interrupt flag kept (D82: an
 * interrupted wait once returned as if the condition held).
 */
final class Polling {

    interface Cond {
        boolean test() throws Exception;
    }

    private Polling() {
    }

    static void until(String what, long timeoutMs, Cond c, Supplier<String> onTimeout) {
        long deadline = System.nanoTime() + timeoutMs * 1_000_000L;
        Exception last = null;
        long pollMs = 2;
        while (System.nanoTime() - deadline < 0) {
            try {
                if (c.test()) {
                    return;
                }
            } catch (InterruptedException e) {
                interrupted(what, e);
            } catch (Exception e) {
                last = e;
            }
            try {
                Thread.sleep(pollMs);
                pollMs = Math.min(50, pollMs * 2);
            } catch (InterruptedException e) {
                interrupted(what, e);
            }
        }
        fail("timed out after " + timeoutMs + " ms waiting for " + what + (last != null ? " (last error " + last + ")" : "")
                + onTimeout.get());
    }

    private static void interrupted(String what, InterruptedException e) {
        Thread.currentThread().interrupt();
        throw new AssertionError("interrupted while waiting for " + what + ": the condition is not known to hold", e);
    }
}
