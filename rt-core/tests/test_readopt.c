/* D61: READOPT, the re-adopt of a RUNNING half: the newest value of the named state segment is
 * taken at the half's next cycle boundary by its re-adopt hook, and the reply says how that
 * went; every half that cannot take it says why and runs on as it was. The probe in a real
 * child process (probe_kit.h). */
#include <errno.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "arflex/host.h"
#include "helper.h"
#include "probe_kit.h"

static uint64_t state_of(struct arflex_port *p)
{
	uint64_t v = 0;

	p->last_seq = 0;
	assert_int_equal(arflex_state_read(p, &v, sizeof(v), NULL), 1);
	return v;
}

static bool state_above(const struct probe_out *o, uint64_t v)
{
	return o->state_value > v;
}

static bool adopt_calls_are(const struct probe_out *o, uint64_t n)
{
	return o->adopt_calls == n;
}

/* A half started without a state (its own count from 0) re-adopts the running half's newest
 * value while it runs: taken at one cycle boundary, before that cycle's update, so its very
 * next published state counts on from it; no cycle is lost or run twice. */
static void readopt_takes_the_newest_value_while_running(void **state)
{
	struct arflex_host a, b;
	struct probe_out o, o2;
	uint64_t before, after;

	(void)state;
	setup_ids("readopt");
	make_env("ARFLEX_PROBE_READOPT=take");
	probe_state = true;
	assert_int_equal(probe_host(&a, "old", 0, 0, true), 0);
	assert_int_equal(probe_host(&b, "1-old", 0, 0, true), 0);
	probe_state = false;
	spawn_ready(&a);
	spawn_ready(&b);
	/* READOPT is for a running half: before START the ADOPT is the way (D41) */
	assert_int_equal(arflex_host_readopt(&b, arflex_host_state(&a)->name, T_CALL), -ENOTCONN);
	assert_int_equal(arflex_host_start(&a, T_CALL), 0);
	assert_true(wait_out(&a, updates_above, 500, false));
	assert_int_equal(arflex_host_start(&b, T_CALL), 0); /* no ADOPT: b counts from 0 */
	assert_true(wait_out(&b, updates_above, 20, false));
	assert_true(read_out(&b, &o));
	assert_int_equal(o.adopt_calls, 0);
	assert_true(o.state_value < state_of(arflex_host_state(&a)));

	before = state_of(arflex_host_state(&a));
	assert_int_equal(arflex_host_readopt(&b, arflex_host_state(&a)->name, T_CALL), 0);
	after = state_of(arflex_host_state(&a));
	assert_true(wait_out(&b, adopt_calls_are, 1, false)); /* its next output */
	assert_true(read_out(&b, &o));
	assert_true(o.adopted >= before); /* the newest value at b's cycle boundary */
	assert_true(o.adopted <= after);
	/* from it on: every state b published since counts on from the adopted value */
	assert_true(wait_out(&b, state_above, o.state_value + 20, false));
	assert_true(read_out(&b, &o2));
	assert_int_equal(o2.adopted, o.adopted);
	assert_true(o2.state_value == o2.adopted + o2.updates);
	/* and keeps step with a: the two states differ by the updates each ran since the
	 * re-adopt, not by b's late start */
	before = state_of(arflex_host_state(&a));
	assert_true(o2.state_value + 200 > before && before + 200 > o2.state_value);

	/* a segment that does not open, an empty name */
	{
		char missing[ARFLEX_OBJ_NAME_SIZE];

		snprintf(missing, sizeof(missing), "/arflex.%s.none.state", rid);
		assert_int_equal(arflex_host_readopt(&b, missing, T_CALL), -ENOENT);
		assert_int_equal(arflex_host_readopt(&b, "", T_CALL), -EINVAL);
	}
	assert_true(read_out(&b, &o));
	assert_int_equal(o.adopt_calls, 1);

	FINISH_PROBES(&a, &b);
}

/* Every re-adopt the half cannot take is refused with its reason, and the half runs on with its
 * own state: no hook (-EOPNOTSUPP), a refusing hook, nothing published (-ENODATA), a type the
 * hook does not understand (-EPROTOTYPE). */
static void readopt_refusals_leave_the_half_as_it_was(void **state)
{
	struct arflex_host a, b, c;
	struct arflex_port empty, other;
	struct arflex_port_spec probe_spec = { .method = ARFLEX_PORT_STATE,
					       .type = { "test.ProbeState", 1, 0, sizeof(uint64_t) } };
	struct arflex_port_spec other_spec = { .method = ARFLEX_PORT_STATE,
					       .type = { "test.Other", 1, 0, sizeof(uint64_t) } };
	char empty_name[ARFLEX_OBJ_NAME_SIZE], other_name[ARFLEX_OBJ_NAME_SIZE];
	struct probe_out o;
	uint64_t v = 9;

	(void)state;
	setup_ids("rarefuse");
	probe_state = true;
	assert_int_equal(probe_host(&a, "old", 0, 0, true), 0);
	assert_int_equal(probe_host(&b, "1-old", 0, 0, true), 0);
	assert_int_equal(probe_host(&c, "2-old", 0, 0, true), 0);
	probe_state = false;
	spawn_ready(&a);
	spawn_ready(&b); /* no re-adopt hook */
	make_env("ARFLEX_PROBE_READOPT=refuse");
	spawn_ready(&c);
	assert_int_equal(arflex_host_start(&a, T_CALL), 0);
	assert_int_equal(arflex_host_start(&b, T_CALL), 0);
	assert_int_equal(arflex_host_start(&c, T_CALL), 0);
	assert_true(wait_out(&a, updates_above, 50, false));
	assert_int_equal(arflex_host_readopt(&b, arflex_host_state(&a)->name, T_CALL), -EOPNOTSUPP);
	assert_int_equal(arflex_host_readopt(&c, arflex_host_state(&a)->name, T_CALL), -EBADMSG);
	assert_true(read_out(&c, &o));
	assert_int_equal(o.adopt_calls, 0);
	assert_true(wait_out(&c, updates_above, o.updates + 10, false)); /* runs on */
	assert_true(read_out(&b, &o));
	assert_int_equal(o.adopt_calls, 0);
	shutdown_ok(&c);
	arflex_host_destroy(&c);

	/* a hook that takes it: nothing published, another type */
	make_env("ARFLEX_PROBE_READOPT=take");
	probe_state = true;
	assert_int_equal(probe_host(&c, "3-old", 0, 0, true), 0);
	probe_state = false;
	spawn_ready(&c);
	assert_int_equal(arflex_host_start(&c, T_CALL), 0);
	snprintf(empty_name, sizeof(empty_name), "/arflex.%s.empty.state", rid);
	assert_int_equal(arflex_port_create(&empty, empty_name, &probe_spec), 0);
	assert_int_equal(arflex_host_readopt(&c, empty_name, T_CALL), -ENODATA);
	snprintf(other_name, sizeof(other_name), "/arflex.%s.other.state", rid);
	assert_int_equal(arflex_port_create(&other, other_name, &other_spec), 0);
	assert_int_equal(arflex_state_write(&other, &v, sizeof(v)), 0);
	assert_int_equal(arflex_host_readopt(&c, other_name, T_CALL), -EPROTOTYPE);
	assert_true(read_out(&c, &o));
	assert_int_equal(o.adopt_calls, 0);
	assert_true(o.state_value == o.updates); /* its own count, untouched */
	assert_true(wait_out(&c, updates_above, o.updates + 10, false));
	/* the same half takes a good one after the refusals */
	assert_int_equal(arflex_host_readopt(&c, arflex_host_state(&a)->name, T_CALL), 0);
	assert_true(wait_out(&c, adopt_calls_are, 1, false));
	assert_int_equal(arflex_port_destroy(&empty), 0);
	assert_int_equal(arflex_port_destroy(&other), 0);

	FINISH_PROBES(&a, &b, &c);
}

/* D70: a half advertises that it can re-adopt (ARFLEX_FLAG_READOPT in ctl.flags) once READY
 * when its configure registered a re-adopt hook, refusing one or not: the DRCR reads it before a
 * shadow run's START, so that a shadowed update of a half that could not take the state at the
 * switch is refused up front. A half without the hook does not advertise it; neither does one
 * that registered NULL. */
static void readopt_capability_is_advertised_at_ready(void **state)
{
	struct arflex_host a, b, c, d;

	(void)state;
	setup_ids("racap");
	probe_state = true;
	assert_int_equal(probe_host(&a, "old", 0, 0, true), 0);
	assert_int_equal(probe_host(&b, "1-old", 0, 0, true), 0);
	assert_int_equal(probe_host(&c, "2-old", 0, 0, true), 0);
	assert_int_equal(probe_host(&d, "3-old", 0, 0, true), 0);
	probe_state = false;
	spawn_ready(&a); /* no re-adopt hook */
	make_env("ARFLEX_PROBE_READOPT=take");
	spawn_ready(&b);
	make_env("ARFLEX_PROBE_READOPT=refuse");
	spawn_ready(&c);
	make_env("ARFLEX_PROBE_READOPT=null");
	spawn_ready(&d);
	assert_int_equal(arflex_ctl_state(a.ctl), ARFLEX_STATE_READY);
	assert_false(arflex_ctl_flags(a.ctl) & ARFLEX_FLAG_READOPT);
	assert_true(arflex_ctl_flags(b.ctl) & ARFLEX_FLAG_READOPT);
	assert_true(arflex_ctl_flags(c.ctl) & ARFLEX_FLAG_READOPT);
	assert_false(arflex_ctl_flags(d.ctl) & ARFLEX_FLAG_READOPT);
	/* kept while running, and what the flag says is what READOPT answers */
	assert_int_equal(arflex_host_start(&a, T_CALL), 0);
	assert_int_equal(arflex_host_start(&b, T_CALL), 0);
	assert_true(wait_out(&a, updates_above, 20, false));
	assert_true(wait_out(&b, updates_above, 5, false));
	assert_true(arflex_ctl_flags(b.ctl) & ARFLEX_FLAG_READOPT);
	assert_false(arflex_ctl_flags(a.ctl) & ARFLEX_FLAG_READOPT);
	assert_int_equal(arflex_host_readopt(&b, arflex_host_state(&a)->name, T_CALL), 0);

	FINISH_PROBES(&a, &b, &c, &d);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(readopt_takes_the_newest_value_while_running),
		cmocka_unit_test(readopt_refusals_leave_the_half_as_it_was),
		cmocka_unit_test(readopt_capability_is_advertised_at_ready),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
