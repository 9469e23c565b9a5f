/* The safety gate fails closed: every way a safety input can be wrong holds the arm. */
#include <errno.h>
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "arflex/port.h"
#include "arflex/safety_gate.h"
#include "helper.h"

#define MS 1000000ull

static char rid[48];

static const struct arflex_port_type safety_type = {
	.name = ARFLEX_TYPE_SAFETY_STATE_NAME,
	.major = ARFLEX_TYPE_SAFETY_STATE_VERSION_MAJOR,
	.minor = ARFLEX_TYPE_SAFETY_STATE_VERSION_MINOR,
	.elem_size = sizeof(struct arflex_safety_state),
};

struct rig {
	struct arflex_port mgr, w, r;
	struct arflex_safety_gate g;
};

static void rig_open(struct rig *x, const char *tag)
{
	struct arflex_port_spec spec = { .method = ARFLEX_PORT_STATE, .type = safety_type };
	char name[ARFLEX_OBJ_NAME_SIZE];

	th_rid(rid, sizeof(rid), tag);
	assert_int_equal(arflex_ctl_obj_name(name, sizeof(name), rid, "guard", "out.safety"), 0);
	assert_int_equal(arflex_port_create(&x->mgr, name, &spec), 0);
	assert_int_equal(arflex_port_open(&x->w, name, true, true, ARFLEX_PORT_STATE, &safety_type), 0);
	assert_int_equal(arflex_port_open(&x->r, name, false, false, ARFLEX_PORT_STATE, &safety_type), 0);
	arflex_safety_gate_init(&x->g, NULL, 20 * MS);
}

static void rig_close(struct rig *x)
{
	arflex_port_close(&x->r);
	arflex_port_close(&x->w);
	assert_int_equal(arflex_port_destroy(&x->mgr), 0);
	th_assert_clean(rid);
}

static void publish(struct rig *x, uint32_t mode, double power)
{
	struct arflex_safety_state s = { .t_ns = 1, .seq = 1, .mode = mode, .power_scale = power,
					 .force_norm = 3.0, .force_limit = 150.0 };

	assert_int_equal(arflex_state_write(&x->w, &s, sizeof(s)), 0);
}

static enum arflex_safety_verdict judge(struct rig *x, uint32_t binding, uint64_t at)
{
	return arflex_safety_gate_judge(&x->g, binding ? &x->r : NULL, binding, at);
}

static void verdicts_fail_closed(void **state)
{
	struct rig x;
	uint64_t now;

	(void)state;
	rig_open(&x, "gate");
	now = arflex_sys_now_ns();
	/* unbound, then bound but silent */
	assert_int_equal(judge(&x, 0, now), ARFLEX_SAFETY_NO_PROVIDER);
	assert_int_equal(judge(&x, 1, now), ARFLEX_SAFETY_NO_VALUE);
	assert_false(arflex_safety_permits(x.g.verdict));
	/* a fresh NORMAL value permits at full power */
	publish(&x, ARFLEX_SAFETY_STATE_MODE_NORMAL, 1.0);
	now = arflex_sys_now_ns();
	assert_int_equal(judge(&x, 1, now), ARFLEX_SAFETY_NORMAL);
	assert_true(arflex_safety_permits(x.g.verdict));
	assert_true(arflex_safety_gate_scale(&x.g) == 1.0);
	/* the same NORMAL value, older than 20 ms: late once (a stall of the whole machine
	 * looks like this to the first cycle after it) is not yet stale ... */
	assert_int_equal(judge(&x, 1, now + 25 * MS), ARFLEX_SAFETY_NORMAL);
	/* ... and a provider that writes right after the stall clears it */
	publish(&x, ARFLEX_SAFETY_STATE_MODE_NORMAL, 1.0);
	now = arflex_sys_now_ns();
	assert_int_equal(judge(&x, 1, now), ARFLEX_SAFETY_NORMAL);
	assert_int_equal(x.g.late_since_ns, 0);
	/* the provider died: late in the consumer's checks over 10 ms (max age / 2): stale */
	assert_int_equal(judge(&x, 1, now + 21 * MS), ARFLEX_SAFETY_NORMAL);
	assert_int_equal(judge(&x, 1, now + 26 * MS), ARFLEX_SAFETY_NORMAL);
	assert_int_equal(judge(&x, 1, now + 31 * MS), ARFLEX_SAFETY_STALE);
	assert_false(arflex_safety_permits(x.g.verdict));
	assert_true(arflex_safety_gate_scale(&x.g) == 0.0);
	/* limited scales, protective stop holds */
	publish(&x, ARFLEX_SAFETY_STATE_MODE_LIMITED, 0.25);
	assert_int_equal(judge(&x, 1, arflex_sys_now_ns()), ARFLEX_SAFETY_LIMITED);
	assert_true(arflex_safety_gate_scale(&x.g) == 0.25);
	publish(&x, ARFLEX_SAFETY_STATE_MODE_PROTECTIVE_STOP, 0.1);
	assert_int_equal(judge(&x, 1, arflex_sys_now_ns()), ARFLEX_SAFETY_STOP);
	assert_false(arflex_safety_permits(x.g.verdict));
	/* invalid values are rejected and counted, and hold until a valid one */
	publish(&x, ARFLEX_SAFETY_STATE_MODE_NORMAL, NAN);
	assert_int_equal(judge(&x, 1, arflex_sys_now_ns()), ARFLEX_SAFETY_INVALID);
	assert_int_equal(judge(&x, 1, arflex_sys_now_ns()), ARFLEX_SAFETY_INVALID);
	publish(&x, ARFLEX_SAFETY_STATE_MODE_NORMAL, 1.5);
	assert_int_equal(judge(&x, 1, arflex_sys_now_ns()), ARFLEX_SAFETY_INVALID);
	publish(&x, 7, 1.0);
	assert_int_equal(judge(&x, 1, arflex_sys_now_ns()), ARFLEX_SAFETY_INVALID);
	assert_int_equal(x.g.rejected, 3);
	publish(&x, ARFLEX_SAFETY_STATE_MODE_NORMAL, 1.0);
	assert_int_equal(judge(&x, 1, arflex_sys_now_ns()), ARFLEX_SAFETY_NORMAL);
	/* another binding (the provider restarted) must speak again before motion */
	assert_int_equal(judge(&x, 2, arflex_sys_now_ns()), ARFLEX_SAFETY_NO_VALUE);
	publish(&x, ARFLEX_SAFETY_STATE_MODE_NORMAL, 1.0);
	assert_int_equal(judge(&x, 2, arflex_sys_now_ns()), ARFLEX_SAFETY_NORMAL);
	/* a header overwritten while mapped */
	x.mgr.hdr->magic = 0;
	assert_int_equal(judge(&x, 2, arflex_sys_now_ns()), ARFLEX_SAFETY_DAMAGED);
	x.mgr.hdr->magic = ARFLEX_PORT_MAGIC;
	assert_string_equal(arflex_safety_verdict_name(ARFLEX_SAFETY_STALE), "stale");
	rig_close(&x);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(verdicts_fail_closed),
	};

	return cmocka_run_group_tests(tests, NULL, NULL);
}
