package org.arflex.drcr.impl.runtime;

import java.util.ArrayList;
import java.util.Iterator;
import java.util.List;
import java.util.Map;
import java.util.function.Consumer;
import org.arflex.drcr.impl.supervisor.RtLauncher;

/**
 * On an operator reset of a FAILED component, and when its RT half ends (a crash, or the kill
 * that follows damage seen while it ran, {@link #probe}): finds its damaged output segments (truncated,
 * header overwritten; {@link RtLauncher.Output#damage}) and removes them (unlink), so that the
 * restart the reset plans creates them anew ({@link Segments#ensure}) instead of failing the
 * producer again on the same damaged segment. Consumers are rebound to the new segment by the
 * plan that restarts the producer.
 */
final class OutputRepair {

    private OutputRepair() {
    }

    /**
     * Removes every damaged segment from {@code outputs} (closing it unlinks it) and logs each.
     *
     * @return one text per removed segment, for the operator's reply; empty when all are intact
     */
    /**
     * A probe for the heartbeat monitor: the first damaged segment of {@code outputs} (a copy
     * taken when the half starts; the outputs stay the same while it runs), or null.
     */
    static java.util.function.Supplier<String> probe(String instance, Map<String, RtLauncher.Output> outputs) {
        List<Map.Entry<String, RtLauncher.Output>> outs = List.copyOf(outputs.entrySet());
        return () -> {
            for (Map.Entry<String, RtLauncher.Output> e : outs) {
                String why = e.getValue().damage();
                if (why != null) {
                    return "output " + instance + "." + e.getKey() + " damaged while running (" + why
                            + "): restarting it with a new segment";
                }
            }
            return null;
        };
    }

    static List<String> dropDamaged(String instance, Map<String, RtLauncher.Output> outputs, Consumer<String> log) {
        List<String> done = new ArrayList<>();
        for (Iterator<Map.Entry<String, RtLauncher.Output>> it = outputs.entrySet().iterator(); it.hasNext();) {
            Map.Entry<String, RtLauncher.Output> e = it.next();
            String why = e.getValue().damage();
            if (why == null) {
                continue;
            }
            e.getValue().close();
            it.remove();
            String line = "output " + instance + "." + e.getKey() + " (" + e.getValue().name() + ") was damaged: "
                    + why + "; recreated for the restart";
            log.accept("arflex: " + line);
            done.add(line);
        }
        return done;
    }
}
