package org.arflex.drcr.dto;

/** What planning or applying a change set gave (docs/DECISIONS.md D35). */
public class ChangeSetDTO {
    /** The actions, as given ({@code install teach}, {@code uninstall trajectory}, {@code set teach mass 30}). */
    public String[] actions;
    /** True when the whole set is admitted (a dry run that would apply, or an applied set). */
    public boolean admitted;
    /** True when the set was switched in. */
    public boolean applied;
    /** Why it was refused or torn down, naming the action and the component; null otherwise. */
    public String refusal;
    /** The text {@code arflex:change} prints: the set, the outcome, then the plan of the whole set. */
    public String text;
    /** From the start of the preparation to the switch, ms (0 for a dry run or a refusal). */
    public double prepareMs;
    /** The switch's actor turn, µs (0 for a dry run or a refusal). */
    public double switchUs;
    /**
     * When the apply came back (ms since the epoch, the runtime's wall clock): set on the sets
     * {@link org.arflex.drcr.ChangeSetService#history} lists; 0 for a dry run (D46).
     */
    public long finishedMillis;
    /**
     * How the apply ended, in the live progress's words ({@code committed}, {@code applied},
     * {@code rolled-back}, {@code rejected-in-shadow}, {@code torn-down} or {@code refused}); set
     * on the sets {@link org.arflex.drcr.ChangeSetService#history} lists; null for a dry run (D62).
     */
    public String outcome;
    /**
     * Each update of the set, in the set's order, as the apply's live progress last showed it
     * (D60): its shadow run's or rollback window's cycles, its shadow run's worst deviation, its
     * verdict and why (D62). Set on the sets {@link org.arflex.drcr.ChangeSetService#history}
     * lists: empty for a set without updates, or refused before the executor accepted it; null
     * for a dry run.
     */
    public UpdateProgressDTO[] updates;
}
