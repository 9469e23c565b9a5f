package org.arflex.drcr.impl.shell;

import java.util.ArrayList;
import java.util.List;
import java.util.Locale;
import java.util.Optional;
import java.util.Set;
import org.arflex.drcr.DrcrService;
import org.arflex.drcr.dto.CellDTO;
import org.arflex.drcr.dto.InstanceDTO;

/**
 * {@code arflex:await}: waits until a component reaches a lifecycle state, or the whole cell is
 * ACTIVE, looking at the cell again on each of its changes ({@link CellWatch}) until a deadline.
 * A component that is not installed yet is waited for; one that FAILED while ACTIVE is awaited
 * ends the wait at once (only an operator reset gives it a new chance).
 */
final class Readiness {

    /** Seconds waited when no {@code --timeout} is given. */
    static final long DEFAULT_TIMEOUT_S = 60;
    static final Set<String> STATES = Set.of("INSTALLED", "UNSATISFIED", "ACTIVE", "DESTROYED", "FAILED");
    static final String USAGE = "usage: await <name> [INSTALLED|UNSATISFIED|ACTIVE|DESTROYED|FAILED] [--timeout <s>]"
            + " | await --cell [--timeout <s>]";

    private final DrcrService drcr;
    private final CellWatch watch;

    Readiness(DrcrService drcr, CellWatch watch) {
        this.drcr = drcr;
        this.watch = watch;
    }

    /** The command: the line to print ({@code error: ...} on timeout or bad arguments). */
    String await(String... args) {
        List<String> rest = new ArrayList<>(List.of(args));
        long timeoutS = DEFAULT_TIMEOUT_S;
        int t = rest.indexOf("--timeout");
        if (t >= 0) {
            if (t + 1 >= rest.size() || !rest.get(t + 1).matches("\\d{1,6}")) {
                return USAGE;
            }
            timeoutS = Long.parseLong(rest.get(t + 1));
            rest.subList(t, t + 2).clear();
        }
        long timeoutNs = timeoutS * 1_000_000_000L;
        try {
            if (rest.size() == 1 && rest.get(0).equals("--cell")) {
                return cell(timeoutNs, timeoutS);
            }
            if (rest.isEmpty() || rest.size() > 2 || rest.get(0).startsWith("-")) {
                return USAGE;
            }
            String state = rest.size() == 2 ? rest.get(1).toUpperCase(Locale.ROOT) : "ACTIVE";
            if (!STATES.contains(state)) {
                return USAGE;
            }
            return component(rest.get(0), state, timeoutNs, timeoutS);
        } catch (InterruptedException e) {
            Thread.currentThread().interrupt();
            return "error: interrupted while waiting";
        }
    }

    private String component(String name, String state, long timeoutNs, long timeoutS) throws InterruptedException {
        CellWatch.Outcome<Optional<InstanceDTO>> o = watch.await(() -> drcr.instance(name),
                i -> i.isPresent() && (i.get().state.equals(state) || gaveUp(i.get(), state)), timeoutNs);
        if (o.last().isEmpty()) {
            return "error: no component '" + name + "' after " + timeoutS + " s (installed: " + names(drcr.cell()) + ")";
        }
        InstanceDTO i = o.last().get();
        if (o.met() && i.state.equals(state)) {
            return name + " " + state + seconds(o.waitedNs());
        }
        return "error: " + name + " is " + i.state + ", not " + state + (gaveUp(i, state) ? "" : ", after " + timeoutS + " s")
                + (i.failureReason == null ? "" : ": " + i.failureReason.strip())
                + (i.state.equals("FAILED") ? " (arflex:reset " + name + " gives it a new chance)" : "");
    }

    private String cell(long timeoutNs, long timeoutS) throws InterruptedException {
        CellWatch.Outcome<CellDTO> o = watch.await(drcr::cell, c -> c.instances.length > 0 && notActive(c).isEmpty(),
                timeoutNs);
        if (o.met()) {
            return "cell ACTIVE: " + o.last().instances.length + " components" + seconds(o.waitedNs());
        }
        List<String> behind = notActive(o.last());
        return behind.isEmpty() ? "error: no components after " + timeoutS + " s"
                : "error: not ACTIVE after " + timeoutS + " s: " + String.join("; ", behind);
    }

    /** A FAILED instance stays so until an operator reset: waiting for it to become ACTIVE is over. */
    private static boolean gaveUp(InstanceDTO i, String state) {
        return state.equals("ACTIVE") && i.state.equals("FAILED");
    }

    private static List<String> notActive(CellDTO c) {
        List<String> out = new ArrayList<>();
        for (InstanceDTO i : c.instances) {
            if (!i.state.equals("ACTIVE")) {
                out.add(i.name + " " + i.state + (i.failureReason == null ? "" : " (" + i.failureReason.strip() + ")"));
            }
        }
        return out;
    }

    private static List<String> names(CellDTO c) {
        List<String> out = new ArrayList<>();
        for (InstanceDTO i : c.instances) {
            out.add(i.name);
        }
        return out;
    }

    private static String seconds(long ns) {
        return String.format(Locale.ROOT, " (after %.1f s)", ns / 1e9);
    }
}
