/**
 * The DRCR's planner: a pure, deterministic library with no OSGi dependency.
 *
 * <ul>
 * <li>{@link org.arflex.planner.Resolver}: incremental matching of inputs to outputs and
 * transitive satisfaction (a greatest fixpoint, so control loops are legal).</li>
 * <li>{@link org.arflex.planner.Admission} and {@link org.arflex.planner.Schedulability}:
 * per CPU fixed-priority schedulability (utilisation bound, then exact response-time
 * analysis), memory and network budgets, refusal of the lowest criticality first.</li>
 * <li>{@link org.arflex.planner.Planner}: the cell state and the one function that turns a
 * {@link org.arflex.planner.Change} into a {@link org.arflex.planner.Plan}, used for the dry run
 * ({@code plan}) and for the real run alike.</li>
 * </ul>
 *
 * All results are sorted and reproducible: the same inputs give the same plan, byte for byte.
 * Instances are not thread-safe; the DRCR calls them from its single actor thread.
 */
@org.osgi.annotation.bundle.Export
@org.osgi.annotation.versioning.Version("0.1.0")
package org.arflex.planner;
