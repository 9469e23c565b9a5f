package org.arflex.drcr.dto;

/**
 * Where the change set being applied is (docs/DECISIONS.md D53), or how the last one ended: a
 * snapshot, made anew at every change of the apply's phase or counters, never changed after.
 * The phases, in order (a set goes through those it needs): {@code checking} (the actions, the
 * bundles, an update's jar through the code gate, the dry run), {@code preparing} (the new RT
 * halves spawned while the cell runs, until READY), {@code shadow} (an update's new version on
 * the running version's inputs, D42), {@code switching} (the one actor turn, D35),
 * {@code window} (an update's rollback window after its switch, D38), {@code bundles} (Felix
 * brought in line with the cell, D43), then {@code done} with its {@link #outcome}.
 */
public class ChangeSetProgressDTO {
    /** The set's actions, as given. */
    public String[] actions;
    /** True until the outcome is known. */
    public boolean running;
    /** The phase now (see above). */
    public String phase;
    /** What the apply does now, in words: which action is prepared, which update is watched. */
    public String step;
    /** The component the phase is about now, or null. */
    public String component;
    /** In {@code shadow} and {@code window}: the new version's cycles so far. */
    public long cycle;
    /** In {@code shadow} and {@code window}: of how many (0 in the other phases). */
    public long cycles;
    /** In {@code shadow}: the compared field ({@code port.field}) closest to its tolerance so far, or null. */
    public String worstField;
    /** Its largest difference from the running version's so far. */
    public double worstDeviation;
    /** Its declared tolerance. */
    public double tolerance;
    /** The phases gone through so far, the current one last. */
    public String[] phases;
    /** When the apply began (ms since the epoch, the runtime's wall clock). */
    public long startedMillis;
    /** When the current phase began (ms since the epoch). */
    public long phaseMillis;
    /**
     * In {@code done}: {@code committed}, {@code applied} (no verdict of a window),
     * {@code rolled-back}, {@code rejected-in-shadow}, {@code torn-down} or {@code refused};
     * null before.
     */
    public String outcome;
    /** In {@code done}: why (the refusal, or the verdict of the updates' windows), or null. */
    public String why;
    /**
     * Each update of the set, in the order the updates appear in it (D60): its own phase,
     * counters and verdict; the fields above show the one whose counters moved last. Kept after
     * the apply ends. Empty for a set without updates, and until the executor accepts the set.
     */
    public UpdateProgressDTO[] updates;
    /** Grows with every snapshot of this runtime: a reader sees whether anything moved. */
    public long seq;
}
