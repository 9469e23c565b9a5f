package org.arflex.drcr.impl.services;

import java.io.IOException;
import java.nio.file.Path;
import java.util.List;
import java.util.function.Consumer;
import org.arflex.contract.Contract;
import org.arflex.drcr.ChangeSetService;
import org.arflex.drcr.dto.ChangeSetDTO;
import org.arflex.drcr.dto.ChangeSetProgressDTO;
import org.arflex.drcr.impl.runtime.Cell;
import org.arflex.drcr.impl.runtime.ChangeSet;
import org.arflex.drcr.impl.runtime.ChangeSetResult;
import org.osgi.framework.Bundle;
import org.osgi.framework.BundleContext;

/**
 * The {@link ChangeSetService} (D35): parses the actions ({@link ChangeSetActions}), finds the
 * bundles behind them, has the executables of the components to install checked by the code
 * gate and extracted, off the actor ({@link ChangeSetBuild}), hands the set to the cell
 * ({@link ChangeSetApply}), and once it is switched brings Felix in line ({@link SetBundles}):
 * the bundles of installed components are started (the extender adopts what the set started)
 * and those of uninstalled ones stopped. Each apply's outcome goes into the history
 * ({@link ChangeSetHistory}).
 */
public final class ChangeSets implements ChangeSetService {

    /** The extender's part: the executable of a component of an installed, not started bundle. */
    @FunctionalInterface
    public interface Executables {
        /** Checks the bundle with the code gate and extracts the component's executable. */
        Path executable(Bundle bundle, Contract c) throws IOException;
    }

    /**
     * A new version of a component, from a jar that passed the code gate (D38); {@code jar}: its
     * bytes, as checked, for the component's bundle to follow once the update is committed.
     */
    public record Version(Contract contract, String from, String how, Extract extract, byte[] jar) {
    }

    /** Extracts a verified version's executable (apply only, never in a dry run). */
    @FunctionalInterface
    public interface Extract {
        Path executable() throws IOException;
    }

    /** Reads a new version of a component: fetched, pinned or signed, its contract read. */
    @FunctionalInterface
    public interface Versions {
        /**
         * @param sha256 the pinned SHA-256, or null: then the jar must be signed by a trusted key
         * @throws IOException saying why the jar is refused or unreadable
         */
        Version read(String component, String location, String sha256) throws IOException;
    }

    private final Cell cell;
    private final ChangeSetBuild build;
    private final SetBundles felix;
    private final ChangeSetApply applies;
    private volatile UpdatedBundles bundles;
    private volatile DeploymentSets deployments;
    /** The outcomes of the sets applied, for {@link #history} (D46). */
    private final ChangeSetHistory history;

    public ChangeSets(Cell cell, BundleContext context, Consumer<String> log) {
        this(cell, context, log, null);
    }

    /** @param kept where the history is kept across restarts (D66), or null: in memory only */
    public ChangeSets(Cell cell, BundleContext context, Consumer<String> log, HistoryStore kept) {
        this.history = new ChangeSetHistory(System::currentTimeMillis, kept);
        this.cell = cell;
        this.build = new ChangeSetBuild(cell, context, log);
        this.felix = new SetBundles(cell, context, log);
        this.applies = new ChangeSetApply(cell, build, felix, () -> bundles);
    }

    /** Where the new versions of updates come from. */
    public void versions(Versions v) {
        build.versions(v);
    }

    /** Who updates the bundle of a committed update (built with the extender, after this service). */
    public void bundles(UpdatedBundles b) {
        bundles = b;
    }

    /** Who applies deployment sets (D45). */
    public void deployments(DeploymentSets d) {
        deployments = d;
        d.recordInto(history); // its refusals before the change set, in the same history (D50)
    }

    @Override
    public ChangeSetDTO deploy(String url, boolean apply) {
        DeploymentSets d = deployments;
        return d != null ? d.deploy(url, apply)
                : ChangeSetAnswers.refused(List.of("deploy " + url), "the DRCR is not started yet");
    }

    /** Where the executables of installs come from (the extender, built after this service). */
    public void executables(Executables e) {
        build.executables(e);
    }

    /** The actions, parsed ({@link ChangeSetActions#parse}). */
    static List<String[]> parse(List<String> actions) {
        return ChangeSetActions.parse(actions);
    }

    @Override
    public ChangeSetDTO plan(List<String> given) {
        List<String> actions = ChangeSetActions.normalized(given);
        List<String[]> parsed;
        try {
            parsed = ChangeSetActions.parse(actions);
        } catch (IllegalArgumentException e) {
            return ChangeSetAnswers.refused(actions, e.getMessage());
        }
        ChangeSet set;
        try {
            set = build.dryRun(parsed);
        } catch (IllegalStateException e) {
            return ChangeSetAnswers.refused(actions, e.getMessage());
        }
        ChangeSetResult r = cell.actor().call(() -> cell.planChangeSet(set), Services.CALL_MS);
        String problems = r.admitted() ? felix.problems(parsed) : null;
        return problems != null ? ChangeSetAnswers.refused(actions, problems) : ChangeSetAnswers.dto(actions, r);
    }

    @Override
    public ChangeSetDTO apply(List<String> actions) {
        // recorded one text per action, whether the shell gave words or the console whole actions
        return history.record(applies.apply(ChangeSetActions.normalized(actions)));
    }

    @Override
    public List<ChangeSetDTO> history() {
        return history.list();
    }

    @Override
    public ChangeSetProgressDTO progress() {
        return cell.changeSetProgress().snapshot();
    }
}
