/*
 * sample_type.h - arflex.Sample 1.0 for the sample pair: the C layout comes from the header
 * generated from contracts/types/arflex.Sample.xml (contracts/include/arflex_types/sample.h,
 * CMake target arflex_types); this adds the port type descriptor rt-core checks segments
 * against. Shared by sample-counter and sample-scaler (the scaler adds this directory to its
 * include path).
 */
#ifndef SAMPLE_TYPE_H
#define SAMPLE_TYPE_H

#include "arflex/port.h"
#include "arflex_types/sample.h"

/** Port type descriptor of arflex.Sample 1.0. */
static const struct arflex_port_type sample_port_type = {
	.name = ARFLEX_TYPE_SAMPLE_NAME,
	.major = ARFLEX_TYPE_SAMPLE_VERSION_MAJOR,
	.minor = ARFLEX_TYPE_SAMPLE_VERSION_MINOR,
	.elem_size = ARFLEX_TYPE_SAMPLE_SIZE,
};

#endif /* SAMPLE_TYPE_H */
