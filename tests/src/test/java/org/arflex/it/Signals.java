package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;

/** Faults from outside: a signal to a process, as an operator's kill(1) sends it. */
final class Signals {

    private Signals() {
    }

    /** Sends {@code SIG<sig>} (e.g. "STOP", "CONT", "9") to {@code pid}; kill(1) must succeed. */
    static void send(long pid, String sig) throws Exception {
        assertEquals(true, tryToSend(pid, sig), "kill -" + sig + " " + pid);
    }

    /**
     * As {@link #send}, for a process that may be gone already: true when it was signalled;
     * false, and nothing sent, for a pid that is not a process (0 or less).
     */
    static boolean tryToSend(long pid, String sig) throws Exception {
        if (pid <= 0) {
            // no process (a DTO's pid of a half that is not running): kill(1) would signal this
            // whole process group, the test and its build with it (a soak froze itself so)
            return false;
        }
        if ("9".equals(sig)) { // SIGKILL from this JVM directly: no kill(1) to spawn first
            return ProcessHandle.of(pid).map(ProcessHandle::destroyForcibly).orElse(false);
        }
        Process p = new ProcessBuilder("kill", "-" + sig, Long.toString(pid)).inheritIO().start();
        return p.waitFor() == 0;
    }
}
