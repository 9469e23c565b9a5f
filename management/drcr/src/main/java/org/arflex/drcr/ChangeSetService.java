package org.arflex.drcr;

import java.util.List;
import org.arflex.drcr.dto.ChangeSetDTO;
import org.arflex.drcr.dto.ChangeSetProgressDTO;

/**
 * Change sets (docs/DECISIONS.md D35): several actions planned, admitted and applied together,
 * all or nothing. An action is one of
 * <ul>
 * <li>{@code install <component>}: a component whose bundle is installed but not started (it
 * shows as INSTALLED); the set starts it, and its bundle once the set is switched;</li>
 * <li>{@code uninstall <component>}: a running component; the set stops it, and its bundle once
 * the set is switched (the bundle must carry no other running component);</li>
 * <li>{@code set <component> <parameter> <value>}: a parameter write, applied in the switch
 * (or, for a component the set installs, before its RT half starts).</li>
 * </ul>
 * Rewiring follows from the plan. {@link #plan} is the dry run; {@link #apply} prepares the new RT
 * halves while the cell runs and switches the consumers to them in one turn of the DRCR's actor.
 */
@org.osgi.annotation.versioning.ProviderType
public interface ChangeSetService {

    /** The plan of the whole set and whether it would be admitted; changes nothing. */
    ChangeSetDTO plan(List<String> actions);

    /**
     * Applies the set, or refuses it whole (then nothing changed). Returns once switched,
     * refused or torn down.
     */
    ChangeSetDTO apply(List<String> actions);

    /**
     * A deployment set (docs/DECISIONS.md D45): the descriptor at {@code url} (https or file;
     * docs/deployment-sets.md) names bundles of new components and updates of running ones, each
     * jar pinned or signed; every jar passes the code gate and the port formats of the new
     * contracts are checked against their peers before anything is installed, then the whole is
     * one change set. {@code apply} false: the dry run (nothing installed, nothing changed).
     * Refused, nothing is left installed.
     *
     * @since 0.7.0
     */
    ChangeSetDTO deploy(String url, boolean apply);

    /**
     * The outcomes of the sets applied in this runtime (refused ones included; dry runs not),
     * newest first, at most 50, each with {@link ChangeSetDTO#finishedMillis} (D46); kept in the
     * DRCR's data area across restarts of the DRCR and of the runtime (D66).
     */
    List<ChangeSetDTO> history();

    /**
     * Where the set being applied is (docs/DECISIONS.md D53): its phase (checking, preparing,
     * shadow, switching, window, bundles), what it does in it, an update's shadow or window
     * cycles so far and the compared field closest to its tolerance; once over, phase
     * {@code done} with the outcome, until the next apply begins. Null when no set was applied
     * in this runtime. A snapshot: reading it never waits for the apply.
     *
     * @since 0.8.0
     */
    ChangeSetProgressDTO progress();
}
