/* rt-core.component.state: The state block (docs/DECISIONS.md D41, D57) with probe components: published every cycle,
 * adopted once at START, the adopt_prepare hook at the ADOPT.
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

static bool adopted_is(const struct probe_out *o, uint64_t v)
{
	return o->adopt_calls == 1 && o->adopted == v;
}

static bool state_above(const struct probe_out *o, uint64_t v)
{
	return o->state_value > v;
}

static uint64_t state_of(struct arflex_port *p)
{
	uint64_t v = 0;

	p->last_seq = 0;
	assert_int_equal(arflex_state_read(p, &v, sizeof(v), NULL), 1);
	return v;
}

/* D41: the state block is published every cycle into the half's own state segment; a second
 * half told that segment by ADOPT takes its newest value over once, at its next START, before
 * its first update; a declared conversion is the hook's; an unknown type refuses the START. */
static void state_published_and_adopted_once(void **state)
{
	struct arflex_host a, b, c;
	struct arflex_port old;
	struct arflex_port_spec old_spec = { .method = ARFLEX_PORT_STATE,
					     .type = { "test.OldProbeState", 0, 3, sizeof(uint64_t) } };
	struct arflex_port_spec other_spec = { .method = ARFLEX_PORT_STATE,
					       .type = { "test.Other", 1, 0, sizeof(uint64_t) } };
	struct probe_out o;
	char old_name[ARFLEX_OBJ_NAME_SIZE], missing[ARFLEX_OBJ_NAME_SIZE];
	uint64_t before, v;

	(void)state;
	setup_ids("state");
	probe_state = true;
	assert_int_equal(probe_host(&a, "old", 0, 0, true), 0);
	assert_int_equal(probe_host(&b, "1-old", 0, 0, true), 0);
	probe_state = false;
	spawn_ready(&a);
	spawn_ready(&b);
	assert_int_equal(arflex_host_start(&a, T_CALL), 0);
	assert_true(wait_out(&a, updates_above, 50, false));
	/* published every cycle: the state segment follows the updates */
	before = state_of(arflex_host_state(&a));
	assert_true(before >= 50);
	assert_true(wait_out(&a, state_above, before + 20, false));
	assert_true(state_of(arflex_host_state(&a)) > before);

	/* ADOPT before START, then START: the newest value of a's segment, once */
	assert_int_equal(arflex_host_adopt(&b, arflex_host_state(&a)->name, T_CALL), 0);
	before = state_of(arflex_host_state(&a));
	assert_int_equal(arflex_host_start(&b, T_CALL), 0);
	assert_true(wait_out(&b, updates_above, 5, false));
	assert_true(read_out(&b, &o));
	assert_int_equal(o.adopt_calls, 1);
	assert_true(o.adopted >= before);                 /* the newest value at b's START */
	assert_true(o.adopted <= state_of(arflex_host_state(&a)));
	/* b continues from it: its first update already counted on from the adopted value */
	assert_true(o.state_value == o.adopted + o.updates);
	assert_int_equal(arflex_host_adopt(&b, arflex_host_state(&a)->name, T_CALL), -EBUSY);
	/* once: a later START does not adopt again */
	assert_int_equal(arflex_host_stop(&b, T_CALL), 0);
	assert_int_equal(arflex_host_start(&b, T_CALL), 0);
	assert_true(wait_out(&b, updates_above, o.updates + 5, false));
	assert_true(read_out(&b, &o));
	assert_int_equal(o.adopt_calls, 1);
	assert_int_equal(arflex_host_stop(&b, T_CALL), 0);

	/* errors: no such segment; a declared conversion; a type the hook refuses */
	snprintf(missing, sizeof(missing), "/arflex.%s.none.state", rid);
	assert_int_equal(arflex_host_adopt(&b, missing, T_CALL), -ENOENT);
	snprintf(old_name, sizeof(old_name), "/arflex.%s.older.state", rid);
	assert_int_equal(arflex_port_create(&old, old_name, &old_spec), 0);
	v = 7;
	assert_int_equal(arflex_state_write(&old, &v, sizeof(v)), 0);
	probe_state = true;
	assert_int_equal(probe_host(&c, "2-old", 0, 0, true), 0);
	probe_state = false;
	spawn_ready(&c);
	assert_int_equal(arflex_host_adopt(&c, old_name, T_CALL), 0);
	assert_int_equal(arflex_host_start(&c, T_CALL), 0);
	assert_true(wait_out(&c, adopted_is, 70, false)); /* test.OldProbeState 0.3: x 10 */
	assert_int_equal(arflex_host_stop(&c, T_CALL), 0);
	assert_int_equal(arflex_port_destroy(&old), 0);
	assert_int_equal(arflex_port_create(&old, old_name, &other_spec), 0);
	assert_int_equal(arflex_state_write(&old, &v, sizeof(v)), 0);
	assert_int_equal(arflex_host_adopt(&c, old_name, T_CALL), 0);
	assert_int_equal(arflex_host_start(&c, T_CALL), -EPROTOTYPE);
	assert_int_equal(arflex_ctl_state(c.ctl), ARFLEX_STATE_READY);
	assert_int_equal(arflex_port_destroy(&old), 0);

	FINISH_PROBES(&a, &b, &c);
}

/* D57: arflex_component_adopt_prepare: the hook runs at the ADOPT with the value published
 * then; the START still adopts the newest value, also when nothing was published after the
 * ADOPT (the hook's read does not consume it); a refusing hook refuses the ADOPT and nothing is
 * adopted. */
static void adopt_prepare_runs_at_the_adopt(void **state)
{
	struct arflex_host a, b, c;
	struct probe_out o;
	uint64_t at_adopt;

	(void)state;
	setup_ids("prep");
	make_env("ARFLEX_PROBE_PREPARE=count");
	probe_state = true;
	assert_int_equal(probe_host(&a, "old", 0, 0, true), 0);
	assert_int_equal(probe_host(&b, "1-old", 0, 0, true), 0);
	assert_int_equal(probe_host(&c, "2-old", 0, 0, true), 0);
	probe_state = false;
	spawn_ready(&a);
	spawn_ready(&b);
	assert_int_equal(arflex_host_start(&a, T_CALL), 0);
	assert_true(wait_out(&a, updates_above, 50, false));
	assert_int_equal(arflex_host_stop(&a, T_CALL), 0); /* nothing published after this */
	at_adopt = state_of(arflex_host_state(&a));
	assert_int_equal(arflex_host_adopt(&b, arflex_host_state(&a)->name, T_CALL), 0);
	assert_int_equal(arflex_host_start(&b, T_CALL), 0);
	assert_true(wait_out(&b, updates_above, 5, false));
	assert_true(read_out(&b, &o));
	assert_int_equal(o.prepare_calls, 1);
	assert_int_equal(o.prepared, at_adopt);
	assert_int_equal(o.adopt_calls, 1); /* the same value, taken again at the START */
	assert_int_equal(o.adopted, at_adopt);
	assert_int_equal(arflex_host_stop(&b, T_CALL), 0);

	make_env("ARFLEX_PROBE_PREPARE=refuse");
	spawn_ready(&c);
	assert_int_equal(arflex_host_adopt(&c, arflex_host_state(&a)->name, T_CALL), -EBADMSG);
	assert_int_equal(arflex_host_start(&c, T_CALL), 0);
	assert_true(wait_out(&c, updates_above, 5, false));
	assert_true(read_out(&c, &o));
	assert_int_equal(o.adopt_calls, 0);
	assert_int_equal(o.prepare_calls, 0);

	FINISH_PROBES(&a, &b, &c);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(state_published_and_adopted_once),
		cmocka_unit_test(adopt_prepare_runs_at_the_adopt),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
