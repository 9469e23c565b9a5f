/*
 * arflex/host_contract.h - the C host API reads a component's contract (contracts/SPEC.md), so
 * that a harness that runs a component's RT half outside the runtime (a unit test, a desk)
 * declares what the contract declares, and nothing re-declared by hand:
 *
 *   static const struct arflex_host_type types[] = { ARFLEX_HOST_TYPE(SAMPLE) };
 *   struct arflex_host_contract c;
 *   struct arflex_host_opts o;
 *   char err[512];
 *
 *   if (arflex_host_load_contract(&c, "pi-velocity.xml", types, 1, err, sizeof(err)))
 *           fail(err);               // "pi-velocity.xml:6:5: [§6.2] ports/out[velocity]/..."
 *   arflex_host_contract_opts(&c, rid, "pi", &o);
 *   o.config.cfg_flags |= ARFLEX_CFG_NO_MLOCK;   // the harness's own choices, if any
 *   arflex_host_create(&h, &o);
 *
 * What is read, and how it maps (the same as the DRCR's ControlSetup and Segments):
 *   - <out> ports: an output segment each, of the KNOWN type's name, version and size (+ max
 *     payload for frame types), with method, depth and overflow from the contract;
 *   - <in> ports: recorded (arflex_host_contract_input) for the harness to bind; no segment;
 *   - <property>: a parameter slot each, in contract order: type, default, bounds (absent:
 *     the type's whole range, +-DBL_MAX for doubles, 0..1 for bools), mutable;
 *   - <timing>, <implementation>, <fault>: period, deadline, priority (0 for a service),
 *     task type, safe mode, heartbeat timeout, orphan hold, moves-hardware; NO_MLOCK for a
 *     service. No CPU affinity: the contract's cpus are the DRCR admission's business.
 *
 * Port types exist only at compile time (the generated headers arflex_types/<type>.h), so the
 * caller passes the table of the types it knows; a contract naming any other type is refused
 * with the known ones listed. The table must outlive @c (a static table, as below).
 *
 * Parsing uses expat, with no DTD (a DOCTYPE is refused, as SPEC §2.2 says), no processing
 * instructions, at most 1 MiB. The Java validator (org.arflex.contract.ContractParser) stays
 * the authority on contracts; this reader checks everything it maps (names, numbers, ranges,
 * port types and methods, duplicates, required elements, unknown elements and attributes) and
 * refuses what it cannot map, but not the rules of what it skips (bind filters, attributes,
 * resources, update, cpus). Not for the RT thread: it allocates and reads a file.
 *
 * Link arflex::host_contract (libarflex_host_contract.a, which needs libexpat); a component
 * executable never needs it.
 */
#ifndef ARFLEX_HOST_CONTRACT_H
#define ARFLEX_HOST_CONTRACT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "arflex/component.h"
#include "arflex/control.h"
#include "arflex/host.h"
#include "arflex/port.h"

#ifdef __cplusplus
extern "C" {
#endif

/** A port type the caller was compiled with: fill it from the generated header with
 *  ARFLEX_HOST_TYPE(SAMPLE) (arflex_types/sample.h) or ARFLEX_HOST_FRAME_TYPE(IMAGE_FRAME). */
struct arflex_host_type {
	const char *name;      /**< "arflex.Sample" */
	uint16_t major;        /**< version of the definition */
	uint16_t minor;
	uint32_t size;         /**< sizeof the C struct */
	uint32_t methods;      /**< bit 0 state, bit 1 stream, bit 2 frame */
	uint32_t max_payload;  /**< frame types: bytes after the struct in one slot; else 0 */
};

/** Table entry of a non-frame type from its generated macros (ARFLEX_TYPE_<T>_*). */
#define ARFLEX_HOST_TYPE(T)                                                                 \
	{ ARFLEX_TYPE_##T##_NAME, ARFLEX_TYPE_##T##_VERSION_MAJOR,                         \
	  ARFLEX_TYPE_##T##_VERSION_MINOR, ARFLEX_TYPE_##T##_SIZE, ARFLEX_TYPE_##T##_METHODS, 0 }
/** Table entry of a frame type (it has ARFLEX_TYPE_<T>_MAX_PAYLOAD). */
#define ARFLEX_HOST_FRAME_TYPE(T)                                                           \
	{ ARFLEX_TYPE_##T##_NAME, ARFLEX_TYPE_##T##_VERSION_MAJOR,                         \
	  ARFLEX_TYPE_##T##_VERSION_MINOR, ARFLEX_TYPE_##T##_SIZE, ARFLEX_TYPE_##T##_METHODS, \
	  ARFLEX_TYPE_##T##_MAX_PAYLOAD }

/** An input port of the contract (the harness binds it; the host creates nothing for it). */
struct arflex_host_input {
	char port[ARFLEX_NAME_SIZE];
	const struct arflex_host_type *type; /**< into the caller's table */
	enum arflex_port_method method;
	bool optional;
	bool safety;
};

/** A loaded contract. Caller-owned storage (about 10 KiB); fields are read-only. */
struct arflex_host_contract {
	char name[49];                        /**< component/@name */
	char executable[65];                  /**< implementation/@executable */
	struct arflex_ctl_config config;      /**< as the DRCR writes it; cpu_mask 0 */
	struct arflex_param_slot params[ARFLEX_PARAM_SLOTS]; /**< descriptors, contract order */
	unsigned nparams;
	char output_ports[ARFLEX_MAX_OUTPUTS][ARFLEX_NAME_SIZE];
	struct arflex_host_output outputs[ARFLEX_MAX_OUTPUTS]; /**< .port: see _opts */
	unsigned noutputs;
	struct arflex_host_input inputs[ARFLEX_MAX_INPUTS];
	unsigned ninputs;
	struct arflex_port_type state;        /**< <state> (D41), when has_state */
	bool has_state;                       /**< declared, and its type is in the table */
};

/**
 * Reads the contract at @path into @c, knowing the port types @types[@ntypes]. Returns 0, or
 * -errno of the file (-ENOENT, -EACCES, ...), or -EINVAL for anything wrong in it; then @c is
 * zeroed (nothing of it is half declared) and @err (@errlen bytes, may be NULL: then stderr)
 * holds one line "path:line:column: [§N] field: what is wrong" (SPEC §15's form; line and
 * column 0 when no position exists), e.g. the file missing, malformed XML, an unknown port
 * type or method, a port declared twice, a bad number, a required element missing.
 */
ARFLEX_API int arflex_host_load_contract(struct arflex_host_contract *c, const char *path,
					 const struct arflex_host_type *types, unsigned ntypes,
					 char *err, size_t errlen);

/** Fills @o for arflex_host_create(): @runtime, @instance, the contract's configuration,
 *  parameters, outputs and state block (D41: when its type is in the table given to the
 *  loader; pointing into @c, which must outlive the create call). */
ARFLEX_API void arflex_host_contract_opts(struct arflex_host_contract *c, const char *runtime,
					  const char *instance, struct arflex_host_opts *o);

/** The input @port of the contract, or NULL. */
ARFLEX_API const struct arflex_host_input *
arflex_host_contract_input(const struct arflex_host_contract *c, const char *port);

#ifdef __cplusplus
}
#endif
#endif /* ARFLEX_HOST_CONTRACT_H */
