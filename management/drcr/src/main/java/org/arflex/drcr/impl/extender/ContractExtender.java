package org.arflex.drcr.impl.extender;

import java.io.IOException;
import java.io.InputStream;
import java.net.URL;
import java.nio.file.Path;
import java.util.ArrayList;
import java.util.List;
import java.util.concurrent.CompletableFuture;
import java.util.concurrent.ExecutionException;
import java.util.concurrent.TimeUnit;
import java.util.concurrent.TimeoutException;
import java.util.function.Consumer;
import org.arflex.contract.Contract;
import org.arflex.drcr.impl.runtime.Cell;
import org.arflex.drcr.impl.runtime.ContractReader;
import org.osgi.framework.Bundle;
import org.osgi.framework.BundleContext;
import org.osgi.framework.BundleEvent;
import org.osgi.util.tracker.BundleTrackerCustomizer;

/**
 * The extender: tracks installed bundles whose manifest has {@code ARFLEX-Contract}. When such
 * a bundle is installed its contracts are read (a bad one is reported and skipped) and its
 * components show as INSTALLED, and it is prepared for its start on a thread of its own (its
 * executables extracted once the code gate admits it; D54); when it starts (by
 * our commands, Felix's {@code start} or {@code update}) its executables are extracted into its
 * data area (or the prepared copies taken) and its components installed into the cell; when it stops (Felix's {@code stop}, {@code uninstall},
 * {@code update}) they are destroyed before the bundle is gone and show as INSTALLED again;
 * when it is uninstalled they disappear. Callbacks come on the framework's thread and wait for
 * the actor, so Felix's command returns only when the cell has followed.
 */
public final class ContractExtender implements BundleTrackerCustomizer<ContractExtender.Tracked> {

    private static final long CALL_MS = 120_000;

    /** What the extender knows of one bundle. */
    public static final class Tracked {
        List<Contract> contracts = List.of();
        /** Names installed into the cell while the bundle is ACTIVE; null when not active. */
        volatile List<String> active;
        /** Executables extracted from this bundle (released when it is updated or uninstalled). */
        final java.util.Set<Path> extracted = new java.util.HashSet<>();
        /** Executables extracted ahead of the next start, by name ({@link StartPreparation}). */
        final java.util.Map<String, Path> prepared = new java.util.HashMap<>();
        /** Counts the bundle's revisions gone: a preparation of an older one extracts nothing. */
        int revision;
    }


    /**
     * Per bundle id, the components that keep running across the bundle's next stop, update and
     * start: a change set's update was committed and the bundle follows it (D43). The stop
     * leaves them in the cell, the start finds them running with the same contract and the cell
     * adopts them.
     */
    private final java.util.Map<Long, java.util.Set<String>> carried = new java.util.concurrent.ConcurrentHashMap<>();

    private final Cell cell;
    private final ContractReader reader;
    private final BundleContext own;
    private final Consumer<String> log;
    private final Extractor extractor;
    private final Admission admission;
    private final StartPreparation preparation;

    /** The code gate: whether a bundle may run its RT halves. */
    @FunctionalInterface
    public interface Admission {
        /** Null when admitted, else why not (naming the bundle and its location). */
        String refusal(Bundle bundle);
    }

    /**
     * @param prepare     the thread that prepares installed bundles for their start (extracts their
     *                    executables once the gate admits them; D54)
     * @param lookAhead   the gate's verdict for that preparation: neither logged nor kept (a bundle
     *                    is judged for its start, when Felix resolves it, as before)
     */
    public ContractExtender(Cell cell, ContractReader reader, BundleContext own, Extractor extractor,
                            Admission admission, java.util.concurrent.Executor prepare, Admission lookAhead,
                            Consumer<String> log) {
        this.admission = admission;
        this.preparation = new StartPreparation(prepare, lookAhead, this::extract, log);
        this.cell = cell;
        this.reader = reader;
        this.own = own;
        this.extractor = extractor;
        this.log = log;
    }

    /** The bundle states the tracker follows. */
    public static final int MASK = Bundle.INSTALLED | Bundle.RESOLVED | Bundle.STARTING | Bundle.ACTIVE | Bundle.STOPPING;

    static String label(Bundle b) {
        return "bundle " + b.getBundleId() + " (" + b.getSymbolicName() + " " + b.getVersion() + ")";
    }

    @Override
    public Tracked addingBundle(Bundle bundle, BundleEvent event) {
        if (bundle.getHeaders().get(ContractReader.HEADER) == null) {
            return null;
        }
        Tracked t = new Tracked();
        read(bundle, t);
        preparation.submit(bundle, t);
        follow(bundle, t);
        return t;
    }

    @Override
    public void modifiedBundle(Bundle bundle, BundleEvent event, Tracked t) {
        if (event != null && event.getType() == BundleEvent.UPDATED) {
            deactivate(bundle, t);
            forget(bundle, t);
            read(bundle, t); // not prepared: Felix starts an updated bundle at once
        }
        follow(bundle, t);
    }

    @Override
    public void removedBundle(Bundle bundle, BundleEvent event, Tracked t) {
        deactivate(bundle, t);
        forget(bundle, t);
    }

    /** Active bundle: components installed; any other state: not. */
    private void follow(Bundle bundle, Tracked t) {
        boolean wantActive = bundle.getState() == Bundle.ACTIVE;
        if (wantActive && t.active == null) {
            activate(bundle, t);
        } else if (!wantActive && t.active != null) {
            deactivate(bundle, t);
        }
    }

    /** Reads the bundle's contracts (problems go to the cell) and registers them as INSTALLED. */
    private void read(Bundle bundle, Tracked t) {
        String header = bundle.getHeaders().get(ContractReader.HEADER);
        String label = label(bundle);
        long t0 = System.nanoTime();
        ContractReader.Result r = reader.read(label, header, path -> {
            URL u = bundle.getEntry(path);
            return u == null ? null : u.openStream();
        });
        log.accept("arflex: " + label + ": contracts read in " + (System.nanoTime() - t0) / 1000 + " us");
        synchronized (t) {
            t.contracts = r.contracts();
        }
        cell.actor().call(() -> {
            for (String p : r.problems()) {
                cell.problem(p);
            }
            for (Contract c : r.contracts()) {
                cell.register(c, bundle.getBundleId());
            }
            return null;
        }, CALL_MS);
    }

    private void forget(Bundle bundle, Tracked t) {
        List<Contract> cs;
        synchronized (t) {
            cs = t.contracts;
            t.contracts = List.of();
            StartPreparation.drop(t);
            // the record of each copy holds a way back into this bundle revision: let both go
            t.extracted.forEach(extractor::forget);
            t.extracted.clear();
        }
        cell.actor().call(() -> {
            for (Contract c : cs) {
                cell.unregister(c.name(), bundle.getBundleId());
            }
            return null;
        }, CALL_MS);
    }

    private void activate(Bundle bundle, Tracked t) {
        String label = label(bundle);
        long t0 = System.nanoTime();
        List<String> installed = new ArrayList<>();
        // Nothing is extracted or spawned from code that did not come through the verified path
        // (issue 16 finding 3): its components stay INSTALLED and the problem says why.
        String refused = t.contracts.isEmpty() ? null : admission.refusal(bundle);
        if (refused != null) {
            String p = refused + "; its RT halves are not started";
            cell.actor().call(() -> {
                cell.problem(p);
                return null;
            }, CALL_MS);
            t.active = installed;
            log.accept("arflex: " + label + " started but not admitted: " + refused);
            return;
        }
        for (Contract c : t.contracts) {
            Path exe;
            try {
                exe = executableFor(bundle, t, c);
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
        t.active = installed;
        log.accept("arflex: " + label + " started: components " + installed + " in " + (System.nanoTime() - t0) / 1000
                + " us");
    }

    /** The executable of {@code c} for this start: the one prepared ahead of it (D54), or extracted now. */
    private Path executableFor(Bundle bundle, Tracked t, Contract c) throws IOException {
        synchronized (t) {
            Path exe = StartPreparation.take(t, c.executable());
            if (exe == null) {
                exe = extract(bundle, c.executable());
                t.extracted.add(exe);
            }
            return exe;
        }
    }

    private void deactivate(Bundle bundle, Tracked t) {
        List<String> all = t.active;
        if (all == null) {
            return;
        }
        t.active = null;
        java.util.Set<String> keep = carried.getOrDefault(bundle.getBundleId(), java.util.Set.of());
        List<String> names = all.stream().filter(n -> !keep.contains(n)).toList();
        if (names.size() < all.size()) {
            log.accept("arflex: " + label(bundle) + " stops for its update: "
                    + all.stream().filter(keep::contains).toList() + " keep running (a committed change-set update)");
        }
        if (names.isEmpty()) {
            return;
        }
        String why = label(bundle) + " stopped";
        List<Contract> cs = t.contracts;
        CompletableFuture<Void> settled = cell.actor().call(() -> {
            CompletableFuture<Void> f = cell.uninstall(names, why);
            // the bundle is still installed: its components show as INSTALLED again
            for (Contract c : cs) {
                if (names.contains(c.name())) {
                    cell.register(c, bundle.getBundleId());
                }
            }
            return f;
        }, CALL_MS);
        // Off the actor: Felix's command returns once the halves stopped in order, or once one
        // of them did not answer; that one is terminated and reaped on a stop thread, and the
        // cell records it (issue 17: a frozen half must not hold the shell).
        if (!cell.actor().inActor()) {
            try {
                settled.get(CALL_MS, TimeUnit.MILLISECONDS);
            } catch (ExecutionException | TimeoutException e) {
                log.accept("arflex: " + why + ": stops not settled: " + e);
            } catch (InterruptedException e) {
                Thread.currentThread().interrupt();
            }
        }
        log.accept("arflex: " + why + ": destroyed " + names);
    }

    /**
     * For a change set (D35), off the actor: the executable of component {@code c} of a bundle
     * that is installed but not started, once the code gate admitted the bundle (the same check
     * and the same extraction as its start). When the set is switched the bundle is started and
     * {@link Cell#install} adopts the component the set started.
     *
     * @throws IOException saying why the gate refused the bundle or the extraction failed
     */
    public Path executable(Bundle bundle, Contract c) throws IOException {
        String refused = admission.refusal(bundle);
        if (refused != null) {
            throw new IOException(refused + "; its RT halves are not started");
        }
        return extract(bundle, c.executable());
    }

    /**
     * The components {@code names} of bundle {@code bundleId} keep running across the bundle's
     * next stop and start (its update to the version they run already, D43), until
     * {@link #carryDone}.
     */
    public void carryOver(long bundleId, java.util.Set<String> names) {
        carried.put(bundleId, java.util.Set.copyOf(names));
    }

    /** Ends {@link #carryOver}: a later stop of the bundle stops its components again. */
    public void carryDone(long bundleId) {
        carried.remove(bundleId);
    }

    /** Copies an executable out of its bundle into a folder; returns where it is. */
    public interface Extractor {
        Path extract(Path dir, String name, Opener source) throws IOException;

        /**
         * The bundle {@code exe} came from was updated or uninstalled: its record (and with it
         * the bundle revision its source reads from) is released; it is never run again.
         */
        void forget(Path exe);
    }

    /** Opens the bundle's entry again (the extractor may need to re-extract it). */
    @FunctionalInterface
    public interface Opener {
        InputStream open() throws IOException;
    }

    /**
     * Hands {@code native/linux-x86_64/<exe>} to the extractor, into the bundle's data area (our
     * own data area when the bundle has none). Every start extracts afresh, except the first
     * after an install or update, which takes the copy {@link StartPreparation} made of the same
     * revision once the gate admitted it (D54); nothing is reused by its timestamp (issue 16
     * finding 5), and every spawn hashes the file against the bytes read from the bundle.
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
        return extractor.extract(dir.toPath(), exe, () -> {
            URL again = bundle.getEntry(ContractReader.NATIVE_DIR + exe);
            if (again == null) {
                throw new IOException("no longer in the bundle");
            }
            return again.openStream();
        });
    }
}
