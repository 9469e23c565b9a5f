package org.arflex.drcr.impl.services;

import java.io.ByteArrayInputStream;
import java.util.List;
import java.util.Set;
import java.util.function.Consumer;
import org.arflex.drcr.impl.runtime.Cell;
import org.arflex.drcr.impl.runtime.Instance;
import org.osgi.framework.Bundle;
import org.osgi.framework.BundleContext;
import org.osgi.framework.BundleException;

/**
 * Once a change set's update is committed (D38), the component's bundle follows it (D43): Felix
 * updates the bundle to the very jar the update ran (the bytes the code gate checked, held since
 * the apply), while the extender carries the running component over the bundle's stop and start,
 * and the cell adopts it when the bundle's start installs the same contract. So {@code lb} shows
 * the version that runs, a later {@code stop}/{@code start} or a restart of the runtime runs it
 * too, and nothing is restarted.
 *
 * <p>A bundle that carries other components too is not updated (its stop would stop them): the
 * command says so and Felix keeps the old revision, as before D43.
 */
public final class UpdatedBundles {

    private final BundleContext context;
    private final Cell cell;
    private final Carrier extender;
    private final Consumer<String> log;

    /** The extender's part: components kept running across their bundle's stop and start. */
    public interface Carrier {
        void carryOver(long bundleId, Set<String> names);

        void carryDone(long bundleId);
    }

    public UpdatedBundles(BundleContext context, Cell cell, Carrier extender, Consumer<String> log) {
        this.context = context;
        this.cell = cell;
        this.extender = extender;
        this.log = log;
    }

    /**
     * Updates bundle {@code bundleId} of {@code component} to {@code jar} (checked by the gate
     * when the update was read), keeping the component running.
     *
     * @return a line for the command's output: what was done, or a warning saying why not
     */
    public String follow(long bundleId, String component, byte[] jar) {
        Bundle b = context.getBundle(bundleId);
        if (b == null) {
            return warn("bundle " + bundleId + " of '" + component + "' is gone: nothing to update in Felix");
        }
        List<String> others = cell.actor().call(() -> cell.namesOfBundle(bundleId), Services.CALL_MS).stream()
                .filter(n -> !n.equals(component)).toList();
        if (!others.isEmpty()) {
            return warn("bundle " + bundleId + " of '" + component + "' also carries " + others + ": Felix keeps its old "
                    + "revision (updating it would stop them); 'lb' shows the old version, and a stop or update of that "
                    + "bundle runs the old version of '" + component + "' again");
        }
        long before = pid(component);
        String old = b.getVersion().toString();
        extender.carryOver(bundleId, Set.of(component));
        try {
            b.update(new ByteArrayInputStream(jar));
        } catch (BundleException | IllegalStateException | SecurityException e) {
            return warn("bundle " + bundleId + " of '" + component + "' could not be updated to the committed version: "
                    + e.getMessage() + "; it stays " + old);
        } finally {
            extender.carryDone(bundleId);
        }
        long after = pid(component);
        String line = "bundle " + bundleId + " updated " + old + " -> " + b.getVersion() + "; '" + component + "' "
                + (after == before ? "kept running (pid " + after + ")" : "runs as pid " + after + " (was " + before + ")");
        log.accept("arflex: change set: " + line);
        return line + "\n";
    }

    private long pid(String component) {
        return cell.actor().call(() -> cell.instance(component).map(Instance::pid).orElse(0L), Services.CALL_MS);
    }

    private String warn(String p) {
        log.accept("arflex: change set: " + p);
        return "warning: " + p + "\n";
    }
}
