package org.arflex.drcr.impl.services;

import java.util.ArrayList;
import java.util.LinkedHashSet;
import java.util.List;
import java.util.Map;
import java.util.Set;
import java.util.function.Consumer;
import org.arflex.drcr.impl.runtime.Cell;
import org.arflex.drcr.impl.runtime.Instance;
import org.osgi.framework.Bundle;
import org.osgi.framework.BundleContext;
import org.osgi.framework.BundleException;

/**
 * Felix brought in line with a change set (D35, D43): before the set, whether Felix can follow
 * it bundle by bundle; once switched, the bundles of installed components started and of
 * uninstalled ones stopped; once an update is committed, its bundle updated to the jar that
 * runs. Without a bundle context (tests) there is nothing to follow.
 */
final class SetBundles {
    private final Cell cell;
    private final BundleContext context;
    private final Consumer<String> log;

    SetBundles(Cell cell, BundleContext context, Consumer<String> log) {
        this.cell = cell;
        this.context = context;
        this.log = log;
    }

    /**
     * Felix follows the cell only bundle by bundle: a bundle whose start or stop would change
     * components the set does not name is refused.
     */
    String problems(List<String[]> parsed) {
        if (context == null) {
            return null;
        }
        Set<String> named = new LinkedHashSet<>();
        for (String[] a : parsed) {
            if (!a[0].equals("set")) {
                named.add(a[1]);
            }
        }
        List<String> problems = new ArrayList<>();
        for (String[] a : parsed) {
            if (a[0].equals("set") || a[0].equals("update")) {
                continue; // an update does not start or stop a bundle (D38)
            }
            Instance inst = CellLookup.find(cell, a[1]);
            if (inst == null) {
                continue; // the cell says so
            }
            Bundle bundle = context.getBundle(inst.bundleId);
            if (bundle == null) {
                problems.add(a[0] + " " + a[1] + ": its bundle " + inst.bundleId + " is gone");
                continue;
            }
            if (a[0].equals("install") && bundle.getState() == Bundle.ACTIVE) {
                problems.add("install " + a[1] + ": its bundle " + inst.bundleId + " is started but the component is not"
                        + " running (see arflex:list for why)");
            }
            List<String> others = cell.actor().call(() -> cell.namesOfBundle(inst.bundleId), Services.CALL_MS)
                    .stream().filter(n -> !named.contains(n)).toList();
            if (!others.isEmpty()) {
                problems.add(a[0] + " " + a[1] + ": its bundle " + inst.bundleId + " also carries " + others
                        + ", which the set does not name");
            }
        }
        return problems.isEmpty() ? null : String.join("; ", problems);
    }

    /** After the switch: the bundles of installed components started, of uninstalled ones stopped. */
    String follow(List<String[]> parsed, Map<String, Long> bundleIds) {
        if (context == null) {
            return "";
        }
        StringBuilder sb = new StringBuilder();
        for (String[] a : parsed) {
            if (a[0].equals("set") || a[0].equals("update")) {
                continue;
            }
            long id = bundleIds.getOrDefault(a[1], -1L);
            Bundle bundle = id < 0 ? null : context.getBundle(id);
            if (bundle == null) {
                continue;
            }
            try {
                if (a[0].equals("install")) {
                    bundle.start();
                } else {
                    bundle.stop();
                }
                sb.append("bundle ").append(id).append(a[0].equals("install") ? " started" : " stopped").append('\n');
            } catch (BundleException | IllegalStateException e) {
                String p = "change set: bundle " + id + " of '" + a[1] + "' could not be "
                        + (a[0].equals("install") ? "started" : "stopped") + ": " + e.getMessage();
                log.accept("arflex: " + p);
                sb.append("warning: ").append(p).append('\n');
            }
        }
        return sb.toString();
    }

    /** After a committed update: its bundle is updated to the jar that runs (D43); {@code b} may be null. */
    static String followUpdates(UpdatedBundles b, List<String[]> parsed, Map<String, Long> bundleIds,
                                Map<String, ChangeSets.Version> read, String verdict) {
        StringBuilder sb = new StringBuilder();
        for (String[] a : parsed) {
            if (b != null && a[0].equals("update") && bundleIds.containsKey(a[1]) && read.containsKey(a[1])
                    && verdict.contains("update " + a[1] + ": committed")) {
                sb.append(b.follow(bundleIds.get(a[1]), a[1], read.get(a[1]).jar()));
            }
        }
        return sb.toString();
    }
}
