package org.arflex.drcr.impl.extender;

import java.io.IOException;
import java.nio.file.Path;
import java.util.List;
import java.util.concurrent.Executor;
import java.util.concurrent.RejectedExecutionException;
import java.util.function.Consumer;
import org.arflex.contract.Contract;
import org.osgi.framework.Bundle;

/**
 * What a contract bundle's start needs and can have before it (D54): while the bundle is only
 * installed, on a thread of its own, once the code gate admits it, its executables are extracted
 * (with their SHA-256 recorded). The start that follows takes the extracted file instead of
 * copying it out of the jar (2-8 ms of install-to-first-cycle, measured under load).
 *
 * <p>Nothing is trusted more than before: the gate's look ahead is neither logged nor kept (a
 * bundle judged while its install is under way may not be readable yet); the start asks the gate
 * again, as it did; the file taken is hashed against its record before it is spawned, as every
 * spawn; and only the first start after an install takes a prepared file (an updated bundle is
 * started by Felix at once, and later starts extract afresh, as they did). A preparation of a
 * revision that is gone (the bundle was updated or uninstalled meanwhile) is dropped and extracts
 * nothing: {@link ContractExtender.Tracked} is locked by both sides.
 *
 * <p>Felix's resolution is not done ahead: a resolve of our own holds Felix's global lock, and a
 * start on another thread that needs it then fails ("Unable to acquire global lock for
 * resolve", seen in UpdateIT).
 */
final class StartPreparation {

    /** Extracts one executable of a bundle; returns where it is. */
    @FunctionalInterface
    interface Extraction {
        Path extract(Bundle bundle, String executable) throws IOException;
    }

    private final Executor thread;
    private final ContractExtender.Admission gate;
    private final Extraction extraction;
    private final Consumer<String> log;

    StartPreparation(Executor thread, ContractExtender.Admission gate, Extraction extraction,
                     Consumer<String> log) {
        this.thread = thread;
        this.gate = gate;
        this.extraction = extraction;
        this.log = log;
    }

    /**
     * Prepares the start of {@code bundle}, installed and not started, with the contracts of
     * {@code t} (called when they were read). Returns at once.
     */
    void submit(Bundle bundle, ContractExtender.Tracked t) {
        List<Contract> contracts;
        int revision;
        synchronized (t) {
            contracts = t.contracts;
            revision = t.revision;
        }
        if (contracts.isEmpty() || (bundle.getState() & (Bundle.INSTALLED | Bundle.RESOLVED)) == 0) {
            return; // starting or active already: the start extracts as it always did
        }
        try {
            thread.execute(() -> prepare(bundle, t, contracts, revision));
        } catch (RejectedExecutionException e) {
            // the DRCR is stopping: the start, if any comes, does it all itself
        }
    }

    private void prepare(Bundle bundle, ContractExtender.Tracked t, List<Contract> contracts, int revision) {
        String label = ContractExtender.label(bundle);
        long t0 = System.nanoTime();
        try {
            if (gate.refusal(bundle) != null) {
                return; // nothing of it is extracted: its start reports the refusal
            }
            int n = 0;
            synchronized (t) {
                if (t.revision != revision || t.active != null
                        || (bundle.getState() & (Bundle.INSTALLED | Bundle.RESOLVED)) == 0) {
                    return;
                }
                for (Contract c : contracts) {
                    if (t.prepared.containsKey(c.executable())) {
                        continue;
                    }
                    Path exe = extraction.extract(bundle, c.executable());
                    t.extracted.add(exe);
                    t.prepared.put(c.executable(), exe);
                    n++;
                }
            }
            log.accept("arflex: " + label + ": prepared for its start (" + n + " executable"
                    + (n == 1 ? "" : "s") + " extracted) in " + (System.nanoTime() - t0) / 1000 + " us");
        } catch (IOException | RuntimeException e) {
            // whatever failed here fails again, and is reported, at the start
            log.accept("arflex: " + label + ": not prepared ahead of its start (" + e.getMessage()
                    + "); the start does it");
        }
    }

    /**
     * The executable prepared for this start, taken (a later start extracts afresh), or null;
     * called with {@code t} locked.
     */
    static Path take(ContractExtender.Tracked t, String executable) {
        return t.prepared.remove(executable);
    }

    /** The bundle's revision is gone: a preparation under way extracts nothing; called with {@code t} locked. */
    static void drop(ContractExtender.Tracked t) {
        t.revision++;
        t.prepared.clear();
    }
}
