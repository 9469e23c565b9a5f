package org.arflex.drcr.impl.services;

import static org.arflex.drcr.impl.services.ChangeSetAnswers.dto;
import static org.arflex.drcr.impl.services.ChangeSetAnswers.refused;

import java.util.HashMap;
import java.util.List;
import java.util.Map;
import java.util.concurrent.CompletableFuture;
import java.util.concurrent.ExecutionException;
import java.util.concurrent.TimeUnit;
import java.util.concurrent.TimeoutException;
import java.util.function.Supplier;
import org.arflex.drcr.dto.ChangeSetDTO;
import org.arflex.drcr.impl.runtime.Cell;
import org.arflex.drcr.impl.runtime.ChangeSet;
import org.arflex.drcr.impl.runtime.ChangeSetProgress;
import org.arflex.drcr.impl.runtime.ChangeSetResult;
import org.arflex.drcr.impl.runtime.Instance;

/**
 * One apply of a change set through the service (D35), on the caller's thread: the actions
 * parsed, Felix's part checked, the new versions read and the dry run, the executables
 * extracted, the set handed to the cell, then Felix brought in line and, for updates, the
 * verdict of their windows awaited. Its phases are published (D53) and it ends with its outcome
 * whichever way it returns; the answer carries the outcome and each update's entry for the
 * history (D62).
 */
final class ChangeSetApply {

    /** How long an apply may take: preparing halves that load models can take seconds. */
    static final long APPLY_MS = 120_000;

    private final Cell cell;
    private final ChangeSetBuild build;
    private final SetBundles felix;
    private final Supplier<UpdatedBundles> bundles;

    ChangeSetApply(Cell cell, ChangeSetBuild build, SetBundles felix, Supplier<UpdatedBundles> bundles) {
        this.cell = cell;
        this.build = build;
        this.felix = felix;
        this.bundles = bundles;
    }

    /** The apply, its phases published (D53), ended with its outcome whichever way it returns. */
    ChangeSetDTO apply(List<String> actions) {
        ChangeSetProgress.Apply p = cell.changeSetProgress().begin(actions);
        String[] verdict = new String[1];
        boolean[] missing = new boolean[1];
        ChangeSetDTO d = null;
        try {
            d = applyOnce(actions, p, verdict, missing);
            return d;
        } finally {
            if (d == null) {
                p.done("refused", "the apply failed: see the runtime's log");
            } else {
                String outcome = ChangeSetProgress.outcomeOf(d.applied, d.refusal, verdict[0], missing[0]);
                p.done(outcome, d.refusal != null ? d.refusal : verdict[0]);
                // the history keeps what the progress showed of each update (D62)
                d.outcome = outcome;
                d.updates = p.updates();
            }
        }
    }

    private ChangeSetDTO applyOnce(List<String> actions, ChangeSetProgress.Apply p, String[] verdictOut,
                                   boolean[] verdictMissing) {
        List<String[]> parsed;
        try {
            parsed = ChangeSetActions.parse(actions);
        } catch (IllegalArgumentException e) {
            return refused(actions, e.getMessage());
        }
        p.phase(ChangeSetProgress.CHECKING, "checking the bundles behind the actions");
        String problems = felix.problems(parsed);
        if (problems != null) {
            return refused(actions, problems);
        }
        // the bundles behind the named components, before the set (an uninstalled one leaves the cell)
        Map<String, Long> bundleIds = new HashMap<>();
        for (String[] a : parsed) {
            Instance i = CellLookup.find(cell, a[1]);
            if (i != null) {
                bundleIds.put(a[1], i.bundleId);
            }
        }
        // refused sets are refused before anything is extracted from a bundle or a jar
        Map<String, ChangeSets.Version> read = new HashMap<>();
        p.phase(ChangeSetProgress.CHECKING, "reading the new versions of updates, the dry run");
        ChangeSet dryRun;
        try {
            dryRun = build.build(parsed, false, read);
        } catch (IllegalStateException e) {
            return refused(actions, e.getMessage());
        }
        ChangeSetResult dry = cell.actor().call(() -> cell.planChangeSet(dryRun), Services.CALL_MS);
        if (!dry.admitted()) {
            return dto(actions, dry);
        }
        ChangeSet set;
        p.phase(ChangeSetProgress.CHECKING, "extracting the executables of installs and updates");
        try {
            set = build.build(parsed, true, read);
        } catch (IllegalStateException e) {
            return refused(actions, e.getMessage());
        }
        CompletableFuture<ChangeSetResult> f = cell.actor().call(() -> cell.applyChangeSet(set, p), Services.CALL_MS);
        ChangeSetResult r;
        try {
            r = f.get(APPLY_MS, TimeUnit.MILLISECONDS);
        } catch (ExecutionException | TimeoutException e) {
            return refused(actions, "no outcome: " + e);
        } catch (InterruptedException e) {
            Thread.currentThread().interrupt();
            return refused(actions, "interrupted");
        }
        ChangeSetDTO d = dto(actions, r);
        if (r.applied() && r.verdict() == null // a set with updates is in their windows now: said after them
                && parsed.stream().anyMatch(a -> a[0].equals("install") || a[0].equals("uninstall"))) {
            p.phase(ChangeSetProgress.BUNDLES, "starting and stopping the bundles of installed and uninstalled components");
        }
        if (r.applied()) {
            d.text += felix.follow(parsed, bundleIds);
        }
        if (r.applied() && r.verdict() != null) {
            // an update's rollback window: the command says how it ended (committed or rolled back, why)
            try {
                String verdict = r.verdict().get(APPLY_MS, TimeUnit.MILLISECONDS);
                verdictOut[0] = verdict;
                if (verdict.contains(": committed")) {
                    p.phase(ChangeSetProgress.BUNDLES, "updating the bundles of committed updates");
                }
                d.text += verdict + "\n" + SetBundles.followUpdates(bundles.get(), parsed, bundleIds, read, verdict);
            } catch (ExecutionException | TimeoutException e) {
                verdictMissing[0] = true;
                d.text += "warning: no verdict of the rollback window yet: " + e + "\n";
            } catch (InterruptedException e) {
                Thread.currentThread().interrupt();
            }
        }
        return d;
    }
}
