/**
 * The planner API: what the DRCR (or any other client) needs to plan changes to a cell.
 *
 * <ul>
 * <li>{@link org.arflex.planner.Planner}: the cell state and the one function that turns a
 * {@link org.arflex.planner.Change} into a {@link org.arflex.planner.Plan}, used for the dry run
 * ({@code plan}) and for the real run alike; read-only queries of the state (contracts, wires,
 * {@link org.arflex.planner.Satisfaction}, capacities, Active set, CPU assignment).</li>
 * <li>{@link org.arflex.planner.Capacities}: what the cell offers (CPUs, memory, network).</li>
 * <li>{@link org.arflex.planner.AdmissionResult}, {@link org.arflex.planner.Decision},
 * {@link org.arflex.planner.CpuLoad}: the admission behind a plan.</li>
 * <li>{@link org.arflex.planner.CpuAdmissionTest}: the schedulability test of one CPU, chosen
 * when the {@code Planner} is made (fixed-priority response-time analysis by default).</li>
 * </ul>
 *
 * The engine (resolver, admission, schedulability analysis, graph algorithms) is in the private
 * package {@code org.arflex.planner.impl}. All results are sorted and reproducible: the same
 * inputs give the same plan, byte for byte. Instances are not thread-safe; the DRCR calls them
 * from its single actor thread.
 *
 * <p>1.0.0 (from 0.1.0): the engine types (Resolver, Admission, Schedulability, ResolveDelta,
 * Graphs, Text) left this package, and CpuAdmissionTest came in (docs/DECISIONS.md D18).
 *
 * <p>1.1.0 (additions): {@link org.arflex.planner.Change.Overlap} and
 * {@code Change.Builder.overlap}, {@link org.arflex.planner.TransientLoad},
 * {@code Plan.transients()}, {@code Plan.transientRefusals()} and the plan constructor that takes
 * them: the load while both halves of a change set's update run (docs/DECISIONS.md D51).
 */
@org.osgi.annotation.bundle.Export
@org.osgi.annotation.versioning.Version("1.2.0")
package org.arflex.planner;
