/*
 * arflex/safety_gate.h - how a component that moves hardware judges its safety input
 * (arflex.SafetyState, the force guard's or a safety controller's output), every cycle.
 *
 * Fail closed (shared SAFETY.md, principle 1): motion is permitted only while the input is
 * bound, its provider has published a value since it was bound, the newest value is younger
 * than the gate's max age, the segment header is intact, and the value is valid (a known mode,
 * a finite power scale in [0, 1], finite forces) and not a protective stop. Anything else is a
 * verdict that holds the arm, with a reason the component reports (arflex_component_hold).
 * A dead, stopped or hung provider's last value ages past max age and is never taken as NORMAL.
 *
 * Stale means "older than max age, in checks spanning at least max age / 2": the consumer's
 * own cycles must have seen the provider silent, so a stall of the whole machine (every
 * process late at once, the consumer included) is not taken for a dead provider when the
 * provider writes again right after it. A dead provider is judged stale 1.5 x max age after
 * its last value at the latest (plus one consumer cycle).
 *
 *   static struct arflex_safety_gate gate;
 *   configure: arflex_component_input(c, "safety", ARFLEX_PORT_STATE, &t, &in);
 *              arflex_safety_gate_init(&gate, in, 20000000);          // 20 ms
 *   update:    enum arflex_safety_verdict v = arflex_safety_gate_check(&gate, now);
 *              if (!arflex_safety_permits(v)) hold ...; else scale by gate.state.power_scale
 *
 * RT safe: no allocation, no blocking, no printing.
 */
#ifndef ARFLEX_SAFETY_GATE_H
#define ARFLEX_SAFETY_GATE_H

#include <stdbool.h>
#include <stdint.h>

#include "arflex/component.h"
#include "arflex_types/safety_state.h"

#ifdef __cplusplus
extern "C" {
#endif

/** What the gate concluded this cycle. The order is the ABI of the control block's hold
 *  word (ARFLEX_HOLD_*, control.h): keep values stable. */
enum arflex_safety_verdict {
	ARFLEX_SAFETY_NORMAL = 0,      /**< motion permitted at full power */
	ARFLEX_SAFETY_LIMITED = 1,     /**< motion permitted at state.power_scale */
	ARFLEX_SAFETY_STOP = 2,        /**< the provider says protective stop */
	ARFLEX_SAFETY_NO_PROVIDER = 3, /**< input unbound */
	ARFLEX_SAFETY_NO_VALUE = 4,    /**< bound, nothing published since the binding */
	ARFLEX_SAFETY_STALE = 5,       /**< newest value older than max age */
	ARFLEX_SAFETY_INVALID = 6,     /**< NaN/Inf/out-of-range value (rejected, counted) */
	ARFLEX_SAFETY_DAMAGED = 7,     /**< segment header no longer what was mapped */
};

struct arflex_safety_gate {
	struct arflex_input *in;
	uint64_t max_age_ns;
	struct arflex_safety_state state; /**< last valid value (read only) */
	bool seen;                        /**< a valid value arrived on the current binding */
	bool bad;                         /**< the newest value read was invalid */
	uint32_t binding;                 /**< arflex_input_binding of @state */
	uint64_t age_ns;                  /**< age of the newest value at the last check */
	uint64_t late_since_ns;           /**< first check that saw age > max age (0: none) */
	uint64_t rejected;                /**< invalid values seen, cumulative */
	enum arflex_safety_verdict verdict;
};

/** Prepares @g for input @in (declared in configure) with freshness limit @max_age_ns. */
ARFLEX_API void arflex_safety_gate_init(struct arflex_safety_gate *g, struct arflex_input *in,
					uint64_t max_age_ns);

/** Reads the input and judges it at @now_ns (CLOCK_MONOTONIC). Returns g->verdict. */
ARFLEX_API enum arflex_safety_verdict arflex_safety_gate_check(struct arflex_safety_gate *g,
							       uint64_t now_ns);

/** The same on an explicit mapping (NULL or @binding 0: unbound); @binding changes when the
 *  provider changes (arflex_input_binding). For tests and for hosts without a component. */
ARFLEX_API enum arflex_safety_verdict arflex_safety_gate_judge(struct arflex_safety_gate *g,
							       struct arflex_port *p,
							       uint32_t binding, uint64_t now_ns);

/** True for the verdicts that permit motion (NORMAL, LIMITED). */
ARFLEX_API bool arflex_safety_permits(enum arflex_safety_verdict v);

/** Power fraction the verdict allows: 1 NORMAL, state.power_scale LIMITED, 0 otherwise. */
ARFLEX_API double arflex_safety_gate_scale(const struct arflex_safety_gate *g);

/** Short English name of a verdict ("stale", "no provider", ...). */
ARFLEX_API const char *arflex_safety_verdict_name(enum arflex_safety_verdict v);

#ifdef __cplusplus
}
#endif
#endif /* ARFLEX_SAFETY_GATE_H */
