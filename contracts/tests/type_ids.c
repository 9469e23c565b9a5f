/*
 * The generated port-type ids (contracts/include/arflex_types, from contracts/types) must equal
 * rt-core's arflex_port_type_hash of the type name: port segment headers carry that hash and
 * both the RT halves and the DRCR check it on attach (contracts/SPEC.md §13.3, rt-core ABI.md).
 */
#include <stdio.h>

#include "arflex/port.h"
#include "arflex_types/all.h"

static int check(const char *name, uint64_t generated)
{
	uint64_t abi = arflex_port_type_hash(name);

	if (abi != generated) {
		fprintf(stderr, "%s: generated id %016llx, rt-core hash %016llx\n", name,
			(unsigned long long)generated, (unsigned long long)abi);
		return 1;
	}
	return 0;
}

#define CHECK(T) check(ARFLEX_TYPE_##T##_NAME, ARFLEX_TYPE_##T##_ID)

int main(void)
{
	int bad = CHECK(IMAGE_FRAME) + CHECK(JOINT_REF) + CHECK(JOINT_STATE) + CHECK(POSE) +
		  CHECK(SAFETY_STATE) + CHECK(SAMPLE) + CHECK(TOOL_STATE) + CHECK(WRENCH);

	if (!bad)
		printf("8 port type ids agree with rt-core's hash\n");
	return bad ? 1 : 0;
}
