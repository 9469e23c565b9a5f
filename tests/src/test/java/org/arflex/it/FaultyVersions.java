package org.arflex.it;

import java.io.IOException;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.nio.file.attribute.PosixFilePermissions;

/**
 * Deliberately faulty builds of a component for the update tests (UpdateSetIT, ShadowRunIT,
 * ReconfigBench, RefusedStartIT): the bundle's real executable, written beside a script that runs
 * it with its arguments and one of rt-core's test faults in its environment: a SIGSEGV in the
 * n-th update after its START (D68), every START refused (D58), every READOPT refused (D61). The
 * script takes the place of the executable in a copy of the bundle, which is then pinned and
 * spawned like any other build.
 */
final class FaultyVersions {

    private FaultyVersions() {
    }

    /**
     * Writes the executable {@code exeEntry} of {@code bundle} into {@code dir} (read and execute
     * for the owner only) and returns a {@code /bin/sh} script that execs it with the script's
     * arguments and rt-core's test fault {@code ARFLEX_FAULT_CRASH_AFTER_CYCLES=<cycles>} in its
     * environment: the half raises SIGSEGV in its {@code cycles}-th update after each START (D68),
     * however long its spawn, READY, shadow start or switch took; {@code who} (the test) is named
     * in the script's comment.
     */
    static byte[] crashingAfterCycles(Path dir, Path bundle, String exeEntry, int cycles, String who) throws IOException {
        return withFault(dir, bundle, exeEntry, "ARFLEX_FAULT_CRASH_AFTER_CYCLES", cycles, who,
                "killed by SIGSEGV in its update " + cycles + " after each START");
    }

    /**
     * As {@link #crashingAfterCycles}, but the script execs the real executable with rt-core's test
     * fault {@code ARFLEX_FAULT_START_ERRNO=<errno>} in its environment: the half comes up READY,
     * takes its BINDs and ADOPT, and refuses every START with {@code -errno} (D58).
     */
    static byte[] refusingStart(Path dir, Path bundle, String exeEntry, int errno, String who) throws IOException {
        return withFault(dir, bundle, exeEntry, "ARFLEX_FAULT_START_ERRNO", errno, who, "refusing every START");
    }

    /**
     * As {@link #refusingStart}, with rt-core's test fault {@code ARFLEX_FAULT_READOPT_ERRNO=<errno>}
     * (D61): the half runs, and refuses every READOPT with {@code -errno}, as a half whose re-adopt
     * hook cannot take the running half's state would.
     */
    static byte[] refusingReadopt(Path dir, Path bundle, String exeEntry, int errno, String who) throws IOException {
        return withFault(dir, bundle, exeEntry, "ARFLEX_FAULT_READOPT_ERRNO", errno, who, "refusing every READOPT");
    }

    /**
     * As {@link #crashingAfterCycles}, with rt-core's test fault {@code
     * ARFLEX_FAULT_LATE_EVERY_CYCLES=<cycles>} (D73): every {@code cycles}-th update after a START
     * spins until 100 us past the next release, one late cycle in {@code cycles}.
     */
    static byte[] lateEvery(Path dir, Path bundle, String exeEntry, int cycles, String who) throws IOException {
        return withFault(dir, bundle, exeEntry, "ARFLEX_FAULT_LATE_EVERY_CYCLES", cycles, who,
                "late in every " + cycles + "th cycle after each START");
    }

    private static byte[] withFault(Path dir, Path bundle, String exeEntry, String fault, int value, String who,
                                    String what) throws IOException {
        String file = exeEntry.substring(exeEntry.lastIndexOf('/') + 1);
        Path real = dir.resolve(file);
        Files.write(real, UpdateSetIT.entry(bundle, exeEntry));
        Files.setPosixFilePermissions(real, PosixFilePermissions.fromString("r-x------"));
        String script = "#!/bin/sh\n"
                + "# " + who + "'s deliberately faulty " + file + ": the real one, " + what + "\n"
                + fault + "=" + value + "\n"
                + "export " + fault + "\n"
                + "exec " + real + " \"$@\"\n";
        return script.getBytes(StandardCharsets.UTF_8);
    }
}
