package org.arflex.it;

import static org.junit.jupiter.api.Assertions.assertTrue;

import java.nio.file.Files;
import java.nio.file.Path;
import org.junit.jupiter.api.Test;

/**
 * A component SDK is only done when its product runs (issue 18): the GUIDE's ported PI loop,
 * built out of tree against the installed SDK and packed as a bundle with the GUIDE's commands
 * by ctest {@code sdk.out_of_tree} (rt-core/tests/sdk/out_of_tree.cmake), is deployed into a
 * real runtime through the verified way in (its SHA-256 pinned), becomes ACTIVE, cycles, and
 * publishes what its contract declares; its parameters are the contract's.
 */
class OutOfTreeBundleIT {

    static final long T = 30_000;
    /** Where ctest sdk.out_of_tree leaves the bundle (the native build runs before this module). */
    static final Path JAR = Path.of(System.getProperty("arflex.root"), "target/native/sdk-test/pi-velocity/pi-velocity.jar");

    /** The count in "pi-velocity.velocity (...): element N, K published", 0 before the first value. */
    static long published(String port) {
        java.util.regex.Matcher m = java.util.regex.Pattern.compile(", (\\d+) published").matcher(port);
        return m.find() ? Long.parseLong(m.group(1)) : 0;
    }

    @Test
    void theGuidesOutOfTreeBundleDeploysAndRuns() throws Exception {
        assertTrue(Files.isRegularFile(JAR), JAR + " is missing: it is built by ctest sdk.out_of_tree (./arflex test runs it"
                + " before the integration tests)");
        try (Runtime rt = new Runtime("out-of-tree")) {
            String r = rt.cmd("arflex:deploy " + JAR.toUri() + " " + Jars.sha256(JAR));
            assertTrue(!r.contains("error") && !r.contains("refused"), "deploy: " + r + "\n" + rt.tail());
            rt.awaitState("ACTIVE", T, "pi-velocity");
            long pid = rt.pid("pi-velocity");
            assertTrue(pid > 0);
            // it cycles: its output has more and more values
            rt.waitUntil("pi-velocity publishing", T, () -> published(rt.cmd("arflex:port pi-velocity velocity")) > 100);
            String ki = rt.cmd("arflex:get pi-velocity ki");
            assertTrue(ki.contains("15"), "ki from the contract: " + ki);
            String list = rt.cmd("arflex:list");
            assertTrue(list.lines().anyMatch(l -> l.startsWith("pi-velocity ") && l.contains("ACTIVE")), list);
        }
    }
}
