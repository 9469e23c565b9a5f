package org.arflex.it;

import java.io.IOException;
import java.math.BigDecimal;
import java.nio.charset.StandardCharsets;
import java.nio.file.Files;
import java.nio.file.Path;
import java.nio.file.attribute.PosixFilePermissions;

/**
 * Deliberately faulty builds of a component for the update tests (UpdateSetIT, ShadowRunIT,
 * ReconfigBench, RefusedStartIT): the bundle's real executable, written beside a script that runs
 * it with its arguments and either kills it by SIGSEGV a fixed time after its spawn or sets
 * rt-core's test fault {@code ARFLEX_FAULT_START_ERRNO} (D58: the half refuses every START). The
 * script takes the place of the executable in a copy of the bundle, which is then pinned and
 * spawned like any other build.
 */
final class FaultyVersions {

    private FaultyVersions() {
    }

    /**
     * Writes the executable {@code exeEntry} of {@code bundle} into {@code dir} (read and execute
     * for the owner only) and returns a {@code /bin/sh} script that execs it with the script's
     * arguments, killed by SIGSEGV {@code afterMs} ms after its spawn; {@code who} (the test) is
     * named in the script's comment.
     */
    static byte[] crashingAfterMs(Path dir, Path bundle, String exeEntry, long afterMs, String who)
            throws IOException {
        String file = exeEntry.substring(exeEntry.lastIndexOf('/') + 1);
        Path real = dir.resolve(file);
        Files.write(real, UpdateSetIT.entry(bundle, exeEntry));
        Files.setPosixFilePermissions(real, PosixFilePermissions.fromString("r-x------"));
        String seconds = BigDecimal.valueOf(afterMs, 3).stripTrailingZeros().toPlainString();
        String script = "#!/bin/sh\n"
                + "# " + who + "'s deliberately faulty " + file + ": the real one, killed by SIGSEGV " + afterMs
                + " ms after its spawn\n"
                + "( sleep " + seconds + "; kill -SEGV $$ ) </dev/null >/dev/null 2>&1 &\n"
                + "exec " + real + " \"$@\"\n";
        return script.getBytes(StandardCharsets.UTF_8);
    }

    /**
     * As {@link #crashingAfterMs}, but the script execs the real executable with rt-core's test
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

    private static byte[] withFault(Path dir, Path bundle, String exeEntry, String fault, int errno, String who,
                                    String what) throws IOException {
        String file = exeEntry.substring(exeEntry.lastIndexOf('/') + 1);
        Path real = dir.resolve(file);
        Files.write(real, UpdateSetIT.entry(bundle, exeEntry));
        Files.setPosixFilePermissions(real, PosixFilePermissions.fromString("r-x------"));
        String script = "#!/bin/sh\n"
                + "# " + who + "'s deliberately faulty " + file + ": the real one, " + what + "\n"
                + fault + "=" + errno + "\n"
                + "export " + fault + "\n"
                + "exec " + real + " \"$@\"\n";
        return script.getBytes(StandardCharsets.UTF_8);
    }
}
