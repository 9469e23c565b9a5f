package org.arflex.drcr.impl.supervisor;

import java.util.Map;
import java.util.Set;
import java.util.TreeMap;

/**
 * The environment an RT half is started with (issue 30 finding 8, issue 32; D80): an explicit
 * one, never the runtime's own, which holds the console's password, whatever a unit file sets
 * and rt-core's test fault variables. A half gets the runtime's {@code PATH}, locale
 * ({@code LANG}, {@code LANGUAGE}, {@code LC_*}) and time zone ({@code TZ}), and
 * {@code ARFLEX_DATA_DIR} (where trajectory and teach keep programs); nothing else, loader
 * variables ({@code LD_PRELOAD}, {@code LD_LIBRARY_PATH}) included.
 *
 * <p>{@code ARFLEX_TEST_HOOKS=1}, without which rt-core ignores its {@code ARFLEX_FAULT_*}
 * variables, is added only when the runtime was started for tests (framework property
 * {@code arflex.test.hooks=true}, which the tests' runtimes set); the runtime's own value of it
 * is never passed on, nor any {@code ARFLEX_FAULT_*}: the tests' deliberately faulty versions
 * set their faults themselves, in a script that runs the real executable.
 */
public final class HalfEnvironment {

    /** The marker rt-core needs before it reads any test fault variable. */
    public static final String TEST_HOOKS = "ARFLEX_TEST_HOOKS";
    private static final Set<String> PASSED = Set.of("PATH", "LANG", "LANGUAGE", "TZ", "ARFLEX_DATA_DIR");

    private HalfEnvironment() {
    }

    /**
     * @param runtime the runtime's environment ({@code System.getenv()})
     * @param testHooks whether the halves may honour rt-core's test faults (a test runtime only)
     */
    public static Map<String, String> of(Map<String, String> runtime, boolean testHooks) {
        Map<String, String> env = new TreeMap<>();
        runtime.forEach((k, v) -> {
            if (PASSED.contains(k) || k.startsWith("LC_")) {
                env.put(k, v);
            }
        });
        if (testHooks) {
            env.put(TEST_HOOKS, "1");
        }
        return Map.copyOf(env);
    }
}
