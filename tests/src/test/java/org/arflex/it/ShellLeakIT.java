package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertEquals;
import static org.junit.jupiter.api.Assertions.assertTrue;

import java.util.regex.Matcher;
import java.util.regex.Pattern;
import org.junit.jupiter.api.Test;

/**
 * Issue 17 finding 2: the heap grew with every command typed into the runtime's console. Gogo's
 * own console runs each line as a child of the gosh job and never lets it go: every command kept
 * its pipes and their buffered streams (4 PrintStreams and about 66 KB a command). The ARFLEX
 * shell (D28) runs each line as a top-level job. After 600 commands and a full GC, the runtime
 * holds no more PrintStreams than before (within a margin for the few that live threads hold).
 */
class ShellLeakIT {

    private static final Pattern PRINT_STREAMS = Pattern.compile("\\s(\\d+)\\s+\\d+\\s+java\\.io\\.PrintStream\\s");

    /** PrintStream instances alive in the runtime JVM after a full GC (the histogram collects first). */
    private static long printStreams(long jvm) throws Exception {
        String out = Jcmd.run(jvm, "GC.class_histogram");
        Matcher m = PRINT_STREAMS.matcher(out);
        return m.find() ? Long.parseLong(m.group(1)) : 0;
    }

    @Test
    void commandsTypedIntoTheConsoleLeaveNothingBehind() throws Exception {
        try (Runtime rt = new Runtime("shell-leak")) {
            long jvm = rt.jvmPid();
            for (int i = 0; i < 50; i++) {
                rt.cmd("echo warm-up " + i); // classes loaded, caches filled
            }
            long before = printStreams(jvm);
            for (int i = 0; i < 300; i++) {
                assertEquals("line " + i, rt.cmd("echo line " + i)); // 600 commands: each cmd sends a marker echo too
            }
            long after = printStreams(jvm);
            System.out.printf("ShellLeakIT: PrintStreams after a full GC: %d before, %d after 600 commands%n", before, after);
            assertTrue(after - before < 60, "the console kept " + (after - before) + " PrintStreams over 600 commands");
            assertTrue(rt.cmd("lb -s").contains("org.arflex.shell"), "the console is the ARFLEX shell's");
        }
    }
}
