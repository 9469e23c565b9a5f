/* sdk.out_of_tree: a harness linked against the installed contract reader (arflex::host_contract,
 * which brings expat through the package config). Usage: contract-check <contract.xml> */
#include <stdio.h>

#include <arflex/host_contract.h>
#include <arflex_types/sample.h>

int main(int argc, char **argv)
{
	static const struct arflex_host_type types[] = { ARFLEX_HOST_TYPE(SAMPLE) };
	static struct arflex_host_contract c;
	char err[512];

	if (argc != 2 || arflex_host_load_contract(&c, argv[1], types, 1, err, sizeof(err))) {
		fprintf(stderr, "contract-check: %s\n", argc == 2 ? err : "usage: contract-check X");
		return 1;
	}
	printf("%s: %u outputs, %u parameters, period %llu ns\n", c.name, c.noutputs, c.nparams,
	       (unsigned long long)c.config.period_ns);
	return 0;
}
