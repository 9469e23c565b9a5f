/*
 * arflex_sim/ground_truth.h - the simulator's evaluation-only ground-truth record (C and C++).
 *
 * sim-robot publishes this record in the state-port segment
 *   /arflex.<rid>.<inst>.out.truth
 * ONLY when the manager created that segment before spawning it (an evaluation run: tests,
 * benchmarks, the evaluation harness). The port is deliberately NOT declared in sim-robot's
 * contract, and its type "eval.GroundTruth" is deliberately NOT a contract port type
 * (contracts/types), so no contract can declare an input of this type and the resolver can
 * never bind an application component to it. See simulator/README.md, "Ground truth".
 *
 * Little endian, 192 bytes, no implicit padding; the layout is pinned by static asserts.
 */
#ifndef ARFLEX_SIM_GROUND_TRUTH_H
#define ARFLEX_SIM_GROUND_TRUTH_H

#include <stddef.h>
#include <stdint.h>

#define ARFLEX_SIM_TRUTH_PORT "truth"
#define ARFLEX_SIM_TRUTH_TYPE_NAME "eval.GroundTruth"
#define ARFLEX_SIM_TRUTH_VERSION_MAJOR 1u
#define ARFLEX_SIM_TRUTH_VERSION_MINOR 0u
#define ARFLEX_SIM_TRUTH_SIZE 192u

struct arflex_sim_ground_truth {
	int64_t t_ns;        /**< [ns] CLOCK_MONOTONIC release time of the period (= joint_state.t_ns) */
	uint64_t seq;        /**< values written (= periods run, update + safe) */
	uint64_t steps;      /**< physics steps done since the process started */
	uint64_t cycles;     /**< periods run since the process started (= seq) */
	double sim_time;     /**< [s] simulated time */
	double p[3];         /**< [m] TRUE TCP position, world (cell) frame */
	double quat[4];      /**< TRUE TCP orientation, unit quaternion w, x, y, z */
	double deflection[6];/**< [rad] series-compliance deflection per joint (0 if rigid) */
	double ext_force[3]; /**< [N] external force applied at the TCP in the last step (world) */
	uint32_t obstacle_contacts; /**< arm/obstacle contacts in the last step */
	uint32_t safe;       /**< 1 while the safe hook (hold) drives the arm */
	uint32_t warnings;   /**< simulator warnings (MuJoCo + refused inputs) */
	uint32_t pad0;
	uint64_t periods;    /**< periods simulated since the process started: one per cycle, plus the
	                          periods a release after a stall caught up (D77; steps =
	                          steps_per_period x periods). Was a reserved 0 before. */
};

#ifdef __cplusplus
static_assert(sizeof(struct arflex_sim_ground_truth) == ARFLEX_SIM_TRUTH_SIZE, "truth size");
static_assert(offsetof(struct arflex_sim_ground_truth, p) == 40, "truth.p");
static_assert(offsetof(struct arflex_sim_ground_truth, periods) == 184, "truth.periods");
#else
_Static_assert(sizeof(struct arflex_sim_ground_truth) == ARFLEX_SIM_TRUTH_SIZE, "truth size");
_Static_assert(offsetof(struct arflex_sim_ground_truth, p) == 40, "truth.p");
#endif

#endif /* ARFLEX_SIM_GROUND_TRUTH_H */
