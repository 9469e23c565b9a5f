package org.arflex.drcr.dto;

/**
 * One update of the change set being applied, or of the last one (docs/DECISIONS.md D60): its
 * shadow run's or rollback window's counters as last published, and its verdict once known. An
 * entry of {@link ChangeSetProgressDTO#updates}, in the order the updates appear in the set; a
 * snapshot, never changed after it is published.
 */
public class UpdateProgressDTO {
    /** The component updated. */
    public String component;
    /**
     * {@code shadow} (its new version on the running version's inputs), {@code window} (its
     * rollback window after the switch), or null while neither has begun (the set is checked or
     * prepared, or the update has no shadow run and the switch has not come).
     */
    public String phase;
    /** Its last progress line in words (the shadow run's or the window's), or null before any. */
    public String step;
    /** In {@code shadow} and {@code window}: the new version's cycles so far (the last seen). */
    public long cycle;
    /** Of how many the shadow run or the window has. */
    public long cycles;
    /**
     * The compared field ({@code port.field}) closest to its tolerance in its shadow run, or null
     * (no shadow run, or nothing compared yet); kept through its window.
     */
    public String worstField;
    /** Its largest difference from the running version's in the shadow run. */
    public double worstDeviation;
    /** Its declared tolerance. */
    public double tolerance;
    /**
     * Its own verdict once known: {@code committed} (its window is over without a rollback),
     * {@code rolled-back} (in its window or at the switch), {@code rejected-in-shadow},
     * {@code refused} (its new half, READY, could not run in shadow: D70, no re-adopt hook), or
     * {@code cancelled} (another update of the set was rejected in its shadow run, or refused
     * before it, so the set was abandoned: {@link #why} names it and its reason, D62); null before, and for an update the
     * set's outcome ended without a verdict of its own (the set refused or torn down).
     */
    public String verdict;
    /**
     * The verdict's text (the log's line; for {@code cancelled}: {@code cancelled: update <c> was
     * rejected in shadow (<its reason>)}), or null.
     */
    public String why;
}
