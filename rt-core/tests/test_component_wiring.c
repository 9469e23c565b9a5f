/* rt-core.component.wiring: What the manager changes in a running probe component: parameters, applied at a cycle
 * boundary and never torn, and its inputs bound and unbound while it runs.
 * (The other jobs of the component API: test_component_*.c; the probe: probe.c, probe_kit.h.) */
#include <errno.h>
#include <setjmp.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmocka.h>

#include "arflex/host.h"
#include "helper.h"
#include "probe_kit.h"

static void params_applied_at_cycle_boundary(void **state)
{
	struct arflex_host h;
	struct probe_out o;
	uint64_t v, seq, deadline;
	int idx;

	(void)state;
	setup_ids("param");
	assert_int_equal(probe_host(&h, "probe", 0, 0, true), 0);
	spawn_ready(&h);
	assert_int_equal(arflex_host_start(&h, T_CALL), 0);
	for (int i = 0; i < 300; i++) {
		assert_int_equal(arflex_host_set_param(&h, "gain", (uint64_t)(i % 2 ? -i : i), &v,
						       T_CALL), 0);
		assert_int_equal((int64_t)v, i % 2 ? -i : i);
	}
	/* the direct path: the manager writes the request into the control block */
	idx = arflex_ctl_param_find(h.ctl, "gain");
	assert_true(idx >= 0);
	seq = arflex_ctl_param_request(h.ctl, (unsigned)idx, 777);
	deadline = arflex_sys_now_ns() + 10 * SEC;
	while (__atomic_load_n(&h.ctl->params[idx].applied_seq, __ATOMIC_ACQUIRE) != seq &&
	       arflex_sys_now_ns() < deadline)
		arflex_sys_sleep_until(arflex_sys_now_ns() + 1000000);
	assert_int_equal(h.ctl->params[idx].applied_seq, seq);
	assert_int_equal(h.ctl->params[idx].applied_status, 0);
	assert_true(wait_out(&h, gain_is, 777, false));
	assert_true(read_out(&h, &o));
	assert_int_equal(o.torn, 0);
	shutdown_ok(&h);
	arflex_host_destroy(&h);
	unlink(logpath);
	th_assert_clean(rid);
}

static void bind_and_unbind_while_running(void **state)
{
	struct arflex_port feed;
	struct arflex_port_spec spec = { .method = ARFLEX_PORT_STATE, .type = value_type };
	struct arflex_host h;
	char feed_name[ARFLEX_OBJ_NAME_SIZE], missing[ARFLEX_OBJ_NAME_SIZE];
	uint64_t v, b1, b2, b3;

	(void)state;
	setup_ids("bind");
	snprintf(feed_name, sizeof(feed_name), "/arflex.%s.feed.out.v", rid);
	snprintf(missing, sizeof(missing), "/arflex.%s.feed.out.none", rid);
	assert_int_equal(arflex_port_create(&feed, feed_name, &spec), 0);
	assert_int_equal(probe_host(&h, "probe", 0, 0, true), 0);
	spawn_ready(&h);
	/* bound before START */
	assert_int_equal(arflex_host_bind(&h, "in", feed_name, T_CALL), 0);
	v = 41;
	assert_int_equal(arflex_state_write(&feed, &v, sizeof(v)), 0);
	assert_int_equal(arflex_host_start(&h, T_CALL), 0);
	assert_true(wait_out(&h, in_is, 41, false));
	b1 = binding_of(&h);
	assert_true(b1 != 0);
	assert_int_equal(arflex_host_unbind(&h, "in", T_CALL), 0);
	assert_true(wait_out(&h, unbound, 0, false));
	assert_true(wait_out(&h, binding_is, 0, false)); /* unbound: binding 0 */
	assert_int_equal(arflex_host_unbind(&h, "in", T_CALL), -ENOTCONN);
	/* bound while running: picked up at a cycle boundary; the same provider bound again is
	 * another binding (it may have restarted) */
	assert_int_equal(arflex_host_bind(&h, "in", feed_name, T_CALL), 0);
	v = 42;
	assert_int_equal(arflex_state_write(&feed, &v, sizeof(v)), 0);
	assert_true(wait_out(&h, in_is, 42, false));
	b2 = binding_of(&h);
	assert_true(b2 != 0 && b2 != b1);
	/* rebinding replaces the old binding, without an unbind in between */
	assert_int_equal(arflex_host_bind(&h, "in", feed_name, T_CALL), 0);
	v = 43;
	assert_int_equal(arflex_state_write(&feed, &v, sizeof(v)), 0);
	assert_true(wait_out(&h, in_is, 43, false));
	b3 = binding_of(&h);
	assert_true(b3 != 0 && b3 != b2 && b3 != b1);
	/* errors */
	assert_int_equal(arflex_host_bind(&h, "in", missing, T_CALL), -ENOENT);
	assert_int_equal(arflex_host_bind(&h, "in", arflex_host_output_name(&h, "out"), T_CALL),
			 -EPROTOTYPE);
	assert_int_equal(arflex_host_bind(&h, "nope", feed_name, T_CALL), -ENOENT);
	assert_true(wait_out(&h, in_is, 43, false)); /* still bound to the feed */
	assert_int_equal(binding_of(&h), b3);          /* a refused bind is not a binding */
	shutdown_ok(&h);
	arflex_host_destroy(&h);
	assert_int_equal(arflex_port_destroy(&feed), 0);
	unlink(logpath);
	th_assert_clean(rid);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(params_applied_at_cycle_boundary),
		cmocka_unit_test(bind_and_unbind_while_running),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
