package org.arflex.planner.impl;

import org.arflex.planner.Plan;

/**
 * The plan of no change in one state of the cell, computed in full, with the trace of its
 * admission run: what {@link PlanEngine#current()} returns and what {@link InstallDryRun}
 * derives the plan of one install from. Valid until the state changes (the next commit).
 *
 * @param plan  the plan of {@code Change.none()}
 * @param trace its admission run
 */
record CurrentPicture(Plan plan, AdmissionTrace trace) {
}
