/* sdk.out_of_tree: a program linked against the installed libarflex_rt.so (arflex::rt_shared). */
#include <stdio.h>

#include <arflex/component.h>

int main(void)
{
	if (arflex_sys_now_ns() == 0 || !arflex_port_name_valid("y") || arflex_port_name_valid(""))
		return 1;
	printf("libarflex_rt.so: ABI %u.%u\n", ARFLEX_ABI_MAJOR, ARFLEX_ABI_MINOR);
	return 0;
}
