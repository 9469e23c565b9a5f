/* The cmocka side of the test kit: the assertion every rt-core suite ends with. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "helper.h"

void th_assert_clean(const char *rid)
{
	int left = th_leftovers(rid);

	if (left)
		th_sweep(rid);
	assert_int_equal(left, 0);
	assert_true(th_no_children());
	assert_int_equal(th_threads(), 1);
}
