package org.arflex.drcr.impl.services;

import java.io.IOException;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.Map;
import java.util.function.Consumer;
import org.arflex.drcr.impl.runtime.Cell;
import org.arflex.drcr.impl.runtime.ChangeSet;
import org.arflex.drcr.impl.runtime.Instance;
import org.osgi.framework.Bundle;
import org.osgi.framework.BundleContext;

/**
 * The cell's {@link ChangeSet} made from the parsed actions (D35, D38, D42): the new version of
 * each update read (fetched, pinned or signed, its contract read: {@link ChangeSets.Versions})
 * once per apply, and, for an apply, the executables of installs and updates checked by the code
 * gate and extracted ({@link ChangeSets.Executables}); a dry run extracts nothing. A jar or an
 * executable that cannot be had refuses the set, naming the action.
 */
final class ChangeSetBuild {
    /** Default rollback window of an update, in cycles of the new version (D38). */
    static final long WINDOW = 1000;

    private final Cell cell;
    private final BundleContext context;
    private final Consumer<String> log;
    private volatile ChangeSets.Versions versions = (n, l, s) -> {
        throw new IOException("the DRCR is not started yet");
    };
    private volatile ChangeSets.Executables executables = (b, c) -> {
        throw new IOException("the DRCR is not started yet");
    };

    ChangeSetBuild(Cell cell, BundleContext context, Consumer<String> log) {
        this.cell = cell;
        this.context = context;
        this.log = log;
    }

    void versions(ChangeSets.Versions v) {
        versions = v;
    }

    void executables(ChangeSets.Executables e) {
        executables = e;
    }

    /** A dry run's set: the new versions read, nothing extracted. */
    ChangeSet dryRun(List<String[]> parsed) {
        return build(parsed, false, new java.util.HashMap<>());
    }

    /**
     * The cell's change set; {@code extract}: the executables of installs and updates are checked
     * and extracted. {@code read}: the new versions of updates read so far (each jar is fetched
     * and checked once per apply).
     *
     * @throws IllegalStateException naming the action that cannot be had, and why
     */
    ChangeSet build(List<String[]> parsed, boolean extract, Map<String, ChangeSets.Version> read) {
        ChangeSet.Builder b = ChangeSet.builder();
        for (String[] a : parsed) {
            switch (a[0]) {
                case "install" -> b.install(a[1], extract ? executable(a[1]) : Path.of("(not extracted in a dry run)"));
                case "update" -> {
                    ChangeSets.Version v = read.get(a[1]);
                    if (v == null) {
                        try {
                            v = versions.read(a[1], a[2], a[3].isEmpty() ? null : a[3]);
                        } catch (IOException | RuntimeException e) {
                            throw new IllegalStateException("update " + a[1] + ": " + e.getMessage());
                        }
                        read.put(a[1], v);
                        log.accept("arflex: change set: update " + a[1] + ": " + v.from() + " (" + v.how() + "), version "
                                + v.contract().version());
                    }
                    Path exe;
                    try {
                        exe = extract ? v.extract().executable() : Path.of("(not extracted in a dry run)");
                    } catch (IOException e) {
                        throw new IllegalStateException("update " + a[1] + ": cannot extract its executable: " + e.getMessage());
                    }
                    List<ChangeSet.Envelope> envelopes = new ArrayList<>();
                    List<ChangeSet.Tolerance> tolerances = new ArrayList<>();
                    for (int k = 6; k < a.length; k++) {
                        String[] e = a[k].split(" ");
                        int dot = e[1].indexOf('.');
                        if (e[0].equals("envelope")) {
                            envelopes.add(new ChangeSet.Envelope(e[1].substring(0, dot), e[1].substring(dot + 1),
                                    Double.parseDouble(e[2]), Double.parseDouble(e[3])));
                        } else {
                            tolerances.add(new ChangeSet.Tolerance(e[1].substring(0, dot), e[1].substring(dot + 1),
                                    Double.parseDouble(e[2])));
                        }
                    }
                    // the command line over the new version's <rollout> (SPEC 12.1) over the defaults (D42)
                    b.add(ChangeSet.rules(a[1], v.contract(), exe, a[2], a[4].isEmpty() ? null : Long.parseLong(a[4]),
                            a[5].isEmpty() ? null : Long.parseLong(a[5]), envelopes, tolerances, WINDOW));
                }
                case "uninstall" -> b.uninstall(a[1]);
                default -> b.set(a[1], a[2], a[3]);
            }
        }
        return b.build();
    }

    private Path executable(String name) {
        Instance inst = CellLookup.find(cell, name);
        Bundle bundle = inst == null || context == null ? null : context.getBundle(inst.bundleId);
        if (bundle == null) {
            return Path.of("/nonexistent/" + name); // the cell refuses the set and says why
        }
        try {
            return executables.executable(bundle, inst.contract());
        } catch (IOException e) {
            throw new IllegalStateException("install " + name + ": " + e.getMessage());
        }
    }
}
