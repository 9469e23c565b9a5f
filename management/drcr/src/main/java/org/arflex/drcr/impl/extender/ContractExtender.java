package org.arflex.drcr.impl.extender;

import java.io.IOException;
import java.io.InputStream;
import java.net.URL;
import java.nio.file.Files;
import java.nio.file.Path;
import java.nio.file.StandardCopyOption;
import java.nio.file.attribute.PosixFilePermissions;
import java.util.ArrayList;
import java.util.List;
import java.util.function.Consumer;
import org.arflex.contract.Contract;
import org.arflex.drcr.impl.runtime.Cell;
import org.arflex.drcr.impl.runtime.ContractReader;
import org.osgi.framework.Bundle;
import org.osgi.framework.BundleContext;
import org.osgi.framework.BundleEvent;
import org.osgi.util.tracker.BundleTrackerCustomizer;

/**
 * The extender: tracks ACTIVE bundles whose manifest has {@code ARFLEX-Contract}. When such a
 * bundle starts (by our commands, Felix's {@code start}, {@code install -s} or {@code update})
 * its contracts are read, its executables extracted into its data area and its components
 * installed; when it stops (Felix's {@code stop}, {@code uninstall}, {@code update}) they are
 * destroyed before the bundle is gone. Callbacks come on the framework's thread and wait for
 * the actor, so Felix's command returns only when the cell has followed.
 */
public final class ContractExtender implements BundleTrackerCustomizer<List<String>> {

    private static final long CALL_MS = 120_000;

    private final Cell cell;
    private final ContractReader reader;
    private final BundleContext own;
    private final Consumer<String> log;

    public ContractExtender(Cell cell, ContractReader reader, BundleContext own, Consumer<String> log) {
        this.cell = cell;
        this.reader = reader;
        this.own = own;
        this.log = log;
    }

    static String label(Bundle b) {
        return "bundle " + b.getBundleId() + " (" + b.getSymbolicName() + " " + b.getVersion() + ")";
    }

    @Override
    public List<String> addingBundle(Bundle bundle, BundleEvent event) {
        String header = bundle.getHeaders().get(ContractReader.HEADER);
        if (header == null) {
            return null;
        }
        String label = label(bundle);
        long t0 = System.nanoTime();
        ContractReader.Result r = reader.read(label, header, path -> {
            URL u = bundle.getEntry(path);
            return u == null ? null : u.openStream();
        });
        for (String p : r.problems()) {
            cell.actor().submit(() -> cell.problem(p));
        }
        long tParsed = System.nanoTime();
        log.accept("arflex: " + label + ": contracts read in " + (tParsed - t0) / 1000 + " us");
        List<String> installed = new ArrayList<>();
        for (Contract c : r.contracts()) {
            Path exe;
            try {
                exe = extract(bundle, c.executable());
            } catch (IOException e) {
                String p = label + ": cannot extract " + ContractReader.NATIVE_DIR + c.executable() + ": " + e.getMessage();
                cell.actor().submit(() -> cell.problem(p));
                continue;
            }
            Boolean ok = cell.actor().call(() -> cell.install(c, bundle.getBundleId(), exe), CALL_MS);
            if (ok) {
                installed.add(c.name());
            }
        }
        log.accept("arflex: " + label + " started: components " + installed + " in "
                + (System.nanoTime() - t0) / 1000 + " us");
        return installed;
    }

    @Override
    public void modifiedBundle(Bundle bundle, BundleEvent event, List<String> names) {
        // ACTIVE -> ACTIVE: nothing to do
    }

    @Override
    public void removedBundle(Bundle bundle, BundleEvent event, List<String> names) {
        String why = label(bundle) + " stopped";
        cell.actor().call(() -> {
            for (String n : names) {
                cell.uninstall(n, why);
            }
            return null;
        }, CALL_MS);
        log.accept("arflex: " + why + ": destroyed " + names);
    }

    /**
     * Copies {@code native/linux-x86_64/<exe>} into the bundle's data area (our own data area
     * when the bundle has none), mode 0700, replacing an older copy atomically.
     */
    Path extract(Bundle bundle, String exe) throws IOException {
        URL u = bundle.getEntry(ContractReader.NATIVE_DIR + exe);
        if (u == null) {
            throw new IOException("not in the bundle");
        }
        BundleContext bc = bundle.getBundleContext();
        java.io.File dir = bc != null ? bc.getDataFile("arflex-native") : null;
        if (dir == null) {
            dir = own.getDataFile("native/" + bundle.getBundleId());
        }
        if (dir == null) {
            throw new IOException("the framework has no data area for bundles");
        }
        Path d = dir.toPath();
        Files.createDirectories(d);
        Path target = d.resolve(exe);
        Path tmp = Files.createTempFile(d, exe, ".tmp");
        try (InputStream in = u.openStream()) {
            Files.copy(in, tmp, StandardCopyOption.REPLACE_EXISTING);
            Files.setPosixFilePermissions(tmp, PosixFilePermissions.fromString("rwx------"));
            Files.move(tmp, target, StandardCopyOption.REPLACE_EXISTING, StandardCopyOption.ATOMIC_MOVE);
        } finally {
            Files.deleteIfExists(tmp);
        }
        return target;
    }
}
