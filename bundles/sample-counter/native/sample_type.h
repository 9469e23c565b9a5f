/*
 * sample_type.h - the C layout of the port type arflex.Sample 1.0 (contracts/types/
 * arflex.Sample.xml): u64 seq, i64 t_ns, f64 value; 24 bytes, little endian, no padding.
 *
 * Local definition: the generated port-type headers (contracts/include/arflex_types/) did not
 * contain arflex.Sample yet when this was written. The static asserts keep it equal to the
 * type definition; switch to the generated header once it exists. Shared by sample-counter
 * and sample-scaler (the scaler adds this directory to its include path).
 */
#ifndef SAMPLE_TYPE_H
#define SAMPLE_TYPE_H

#include <stddef.h>
#include <stdint.h>

#include "arflex/port.h"

struct sample_value {
	uint64_t seq;   /**< sequence number, incremented by the writer for every value */
	int64_t t_ns;   /**< CLOCK_MONOTONIC time the value refers to */
	double value;   /**< the sample */
};

_Static_assert(sizeof(struct sample_value) == 24, "arflex.Sample is 24 bytes");
_Static_assert(offsetof(struct sample_value, t_ns) == 8, "arflex.Sample.t_ns at 8");
_Static_assert(offsetof(struct sample_value, value) == 16, "arflex.Sample.value at 16");

/** Port type descriptor of arflex.Sample 1.0. */
static const struct arflex_port_type sample_port_type = {
	.name = "arflex.Sample",
	.major = 1,
	.minor = 0,
	.elem_size = sizeof(struct sample_value),
};

#endif /* SAMPLE_TYPE_H */
