package org.arflex.it;

import java.nio.charset.StandardCharsets;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;

/** The JDK's jcmd against a runtime JVM (heap dumps, histograms, GC): faults and figures from outside. */
final class Jcmd {

    private Jcmd() {
    }

    /** Runs {@code jcmd <pid> <command...>}; its output, or an AssertionError with it when jcmd fails. */
    static String run(long pid, String... command) throws Exception {
        List<String> cmd = new ArrayList<>();
        cmd.add(Path.of(ProcessHandle.current().info().command().orElseThrow()).resolveSibling("jcmd").toString());
        cmd.add(Long.toString(pid));
        cmd.addAll(List.of(command));
        Process p = new ProcessBuilder(cmd).redirectErrorStream(true).start();
        String out = new String(p.getInputStream().readAllBytes(), StandardCharsets.UTF_8);
        if (p.waitFor() != 0) {
            throw new AssertionError(String.join(" ", cmd) + ": " + out);
        }
        return out;
    }
}
