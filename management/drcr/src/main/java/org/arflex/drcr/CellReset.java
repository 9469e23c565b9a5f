package org.arflex.drcr;

import java.util.ArrayList;
import java.util.LinkedHashMap;
import java.util.List;
import java.util.Map;
import java.util.function.Consumer;
import org.arflex.drcr.dto.InstanceDTO;

/**
 * One cell-level reset ({@code arflex:reset --cell}): resets every instance that waits (awaiting
 * an operator reset, in safe mode, or FAILED) in dependency order, and says what it did. The order
 * is found by trying: a reset refused because its cause persists (a safety provider that is
 * itself still stopped) is tried again after the others, as long as a round resets something, so
 * providers are reset before their consumers, cycles included (the guard reads the robot's wrench
 * and the robot the guard's state). A reset never starts motion (SAFETY.md 2). Since 0.4.0, for
 * every client that resets the cell (the shell's {@code arflex:reset --cell}, the console's cell
 * page).
 */
public final class CellReset {

    private CellReset() {
    }

    /**
     * @param reset resets one instance by name (its ComponentManagement); a refusal is a
     *              RuntimeException whose message says why
     * @return what was reset and what was refused, one line each
     */
    public static String run(DrcrService drcr, Consumer<String> reset) {
        List<String> waiting = new ArrayList<>();
        for (InstanceDTO i : drcr.cell().instances) {
            if (i.awaitingReset || i.safeMode || "FAILED".equals(i.state)) {
                waiting.add(i.name);
            }
        }
        if (waiting.isEmpty()) {
            return "cell: nothing waits for a reset";
        }
        Map<String, String> refused = new LinkedHashMap<>();
        List<String> done = new ArrayList<>();
        boolean progress = true;
        while (progress && !waiting.isEmpty()) {
            progress = false;
            for (String n : new ArrayList<>(waiting)) {
                try {
                    reset.accept(n);
                    done.add(n);
                    waiting.remove(n);
                    refused.remove(n);
                    progress = true;
                } catch (RuntimeException e) {
                    refused.put(n, e.getMessage());
                }
            }
        }
        StringBuilder sb = new StringBuilder("cell: reset ").append(done.isEmpty() ? "nothing" : String.join(", ", done));
        for (var e : refused.entrySet()) {
            sb.append("\n  refused ").append(e.getKey()).append(": ").append(e.getValue());
        }
        if (!done.isEmpty()) {
            sb.append("\n  motion sources wait for a fresh command (a program or run true; a tool: its command)");
        }
        return sb.toString();
    }
}
