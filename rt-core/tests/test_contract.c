/* The host API reads a component contract (host_contract.h): the porting guide's contract and
 * one with every kind of port and property map as the DRCR maps them; an instance created
 * from a contract has its parameters and outputs; every bad input is refused with the file,
 * line and what is wrong, and leaves nothing declared. */
#include <dirent.h>
#include <errno.h>
#include <float.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmocka.h>

#include "arflex/host_contract.h"
#include "arflex_types/image_frame.h"
#include "arflex_types/safety_state.h"
#include "arflex_types/sample.h"
#include "helper.h"

#define MS UINT64_C(1000000)

static const struct arflex_host_type TYPES[] = {
	ARFLEX_HOST_TYPE(SAMPLE),
	ARFLEX_HOST_TYPE(SAFETY_STATE),
	ARFLEX_HOST_FRAME_TYPE(IMAGE_FRAME),
};
#define NTYPES ((unsigned)(sizeof(TYPES) / sizeof(TYPES[0])))

static char dir[64];              /* the test's files, removed at the end */
static struct arflex_host_contract c;
static char err[512];

static void write_file(const char *path, const char *text)
{
	FILE *f = fopen(path, "w");

	assert_non_null(f);
	assert_int_equal(fputs(text, f) >= 0, 1);
	assert_int_equal(fclose(f), 0);
}

static int load(const char *path)
{
	return arflex_host_load_contract(&c, path, TYPES, NTYPES, err, sizeof(err));
}

static const struct arflex_param_slot *param(const char *name)
{
	for (unsigned i = 0; i < c.nparams; i++)
		if (!strcmp(c.params[i].name, name))
			return &c.params[i];
	return NULL;
}

static void assert_f64_param(const char *name, double def, double lo, double hi, bool mut)
{
	const struct arflex_param_slot *p = param(name);

	assert_non_null(p);
	assert_int_equal(p->type, ARFLEX_PARAM_DOUBLE);
	assert_true(arflex_bits_f64(p->default_bits) == def);
	assert_true(arflex_bits_f64(p->min_bits) == lo);
	assert_true(arflex_bits_f64(p->max_bits) == hi);
	assert_int_equal(p->flags, mut ? ARFLEX_PARAM_MUTABLE : 0);
}

static void assert_state_sample_out(unsigned i, const char *name)
{
	const struct arflex_port_spec *s = &c.outputs[i].spec;

	assert_string_equal(c.output_ports[i], name);
	assert_int_equal(s->method, ARFLEX_PORT_STATE);
	assert_string_equal(s->type.name, "arflex.Sample");
	assert_int_equal(s->type.major, 1);
	assert_int_equal(s->type.minor, 0);
	assert_int_equal(s->type.elem_size, sizeof(struct arflex_sample));
	assert_int_equal(s->depth, 1);
	assert_int_equal(s->overflow, ARFLEX_OVERFLOW_NONE);
}

/* rt-core/template/bundle/pi-velocity.xml, the contract of the porting guide. */
static void loads_the_guide_contract(void **state)
{
	(void)state;
	assert_int_equal(load(PI_VELOCITY_XML), 0);
	assert_string_equal(err, "");
	assert_string_equal(c.name, "pi-velocity");
	assert_string_equal(c.executable, "pi-velocity");
	assert_int_equal(c.noutputs, 2);
	assert_state_sample_out(0, "velocity");
	assert_state_sample_out(1, "command");
	assert_int_equal(c.ninputs, 0);
	assert_int_equal(c.nparams, 3);
	assert_string_equal(c.params[0].name, "kp"); /* contract order */
	assert_f64_param("kp", 1.0, 0.0, 100.0, true);
	assert_f64_param("ki", 15.0, 0.0, 1000.0, true);
	assert_f64_param("setpoint", 1.0, -10.0, 10.0, true);
	assert_int_equal(c.config.period_ns, 1 * MS);
	assert_int_equal(c.config.deadline_ns, 1 * MS);
	assert_int_equal(c.config.priority, 60);
	assert_int_equal(c.config.task_type, ARFLEX_TASK_PERIODIC);
	assert_int_equal(c.config.safe_mode, ARFLEX_SAFE_ZERO);
	assert_int_equal(c.config.hb_timeout_ns, 100 * MS);
	assert_int_equal(c.config.orphan_hold_ns, 2000 * MS); /* the default */
	assert_int_equal(c.config.cpu_mask, 0);
	assert_int_equal(c.config.cfg_flags, 0);
	assert_int_equal(c.config.param_count, 3);
}

static const char EVERY_KIND[] =
	"<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
	"<!-- every kind of port and property -->\n"
	"<component xmlns=\"urn:arflex:contract:1\" name=\"every-kind\" version=\"2.1.0-rc.1\">\n"
	"  <description>All of it.</description>\n"
	"  <implementation executable=\"every_kind.bin\" task=\"sporadic\" movesHardware=\"true\" motionThrough=\"outputs\"/>\n"
	"  <attributes><attribute name=\"role\" value=\"arm\"/></attributes>\n"
	"  <ports>\n"
	"    <in name=\"x\" type=\"arflex.Sample\" typeVersion=\"1.0\" method=\"stream\" optional=\"true\">\n"
	"      <bind component=\"src\" port=\"y\"/>\n"
	"    </in>\n"
	"    <in name=\"guard\" type=\"arflex.SafetyState\" typeVersion=\"1.0\" method=\"state\" safety=\"true\"/>\n"
	"    <out name=\"log\" type=\"arflex.Sample\" typeVersion=\"1.0\" method=\"stream\" depth=\"64\" overflow=\"drop-newest\"/>\n"
	"    <out name=\"trace\" type=\"arflex.Sample\" typeVersion=\"1.0\" method=\"stream\" depth=\" 8 \"/>\n"
	"    <out name=\"cam\" type=\"arflex.ImageFrame\" typeVersion=\"1.0\" method=\"frame\" depth=\"4\"/>\n"
	"  </ports>\n"
	"  <properties>\n"
	"    <property name=\"on\" type=\"bool\" default=\"true\">A switch.</property>\n"
	"    <property name=\"n\" type=\"int\" default=\"-3\" mutable=\"false\"/>\n"
	"    <property name=\"k.max\" type=\"int\" default=\"+7\" min=\"-10\" max=\"10\" unit=\"1\" mutable=\"true\"/>\n"
	"    <property name=\"g\" type=\"double\" default=\" .5e1 \"/>\n"
	"  </properties>\n"
	"  <timing period=\"2ms\" deadline=\"1500us\" wcet=\"100us\" priority=\"80\" cpus=\"1\" exclusive=\"false\"/>\n"
	"  <resources memory=\"16MiB\" network=\"0\"/>\n"
	"  <criticality> 7 </criticality>\n"
	"  <fault restart=\"transient\" intensity=\"5\" window=\"1s\" backoff=\"0ms\" safe=\"hold\" heartbeatTimeout=\"50ms\" orphanHold=\"0ms\"/>\n"
	"  <update url=\"file:/opt/x.jar\" sha256=\"9f86d081884c7d659a2feaa0c55ad015a3bf4f1b2b0b822cd15d6c15b0f00a08\"/>\n"
	"</component>\n";

static void loads_every_kind(void **state)
{
	char path[128];
	const struct arflex_host_input *x, *g;
	const struct arflex_param_slot *p;

	(void)state;
	snprintf(path, sizeof(path), "%s/every-kind.xml", dir);
	write_file(path, EVERY_KIND);
	assert_int_equal(load(path), 0);
	assert_string_equal(c.name, "every-kind");
	assert_string_equal(c.executable, "every_kind.bin");
	/* inputs: recorded, not created */
	assert_int_equal(c.ninputs, 2);
	x = arflex_host_contract_input(&c, "x");
	g = arflex_host_contract_input(&c, "guard");
	assert_non_null(x);
	assert_non_null(g);
	assert_null(arflex_host_contract_input(&c, "log"));
	assert_ptr_equal(x->type, &TYPES[0]);
	assert_int_equal(x->method, ARFLEX_PORT_STREAM);
	assert_true(x->optional && !x->safety);
	assert_ptr_equal(g->type, &TYPES[1]);
	assert_true(g->optional && g->safety); /* a safety input is optional */
	/* outputs */
	assert_int_equal(c.noutputs, 3);
	assert_string_equal(c.output_ports[0], "log");
	assert_int_equal(c.outputs[0].spec.method, ARFLEX_PORT_STREAM);
	assert_int_equal(c.outputs[0].spec.depth, 64);
	assert_int_equal(c.outputs[0].spec.overflow, ARFLEX_OVERFLOW_DROP_NEWEST);
	assert_int_equal(c.outputs[1].spec.depth, 8);
	assert_int_equal(c.outputs[1].spec.overflow, ARFLEX_OVERFLOW_DROP_OLDEST);
	assert_string_equal(c.output_ports[2], "cam");
	assert_int_equal(c.outputs[2].spec.method, ARFLEX_PORT_FRAME);
	assert_int_equal(c.outputs[2].spec.depth, 4);
	/* a frame slot holds the struct and the payload, as the DRCR sizes it */
	assert_int_equal(c.outputs[2].spec.type.elem_size,
			 ARFLEX_TYPE_IMAGE_FRAME_SIZE + ARFLEX_TYPE_IMAGE_FRAME_MAX_PAYLOAD);
	assert_int_equal(c.outputs[2].spec.overflow, ARFLEX_OVERFLOW_NONE);
	/* properties, with the whole range of their type when no bounds are given */
	assert_int_equal(c.nparams, 4);
	p = param("on");
	assert_int_equal(p->type, ARFLEX_PARAM_BOOL);
	assert_true(p->default_bits == 1 && p->min_bits == 0 && p->max_bits == 1);
	p = param("n");
	assert_int_equal(p->type, ARFLEX_PARAM_INT64);
	assert_true((int64_t)p->default_bits == -3 && (int64_t)p->min_bits == INT64_MIN &&
		    (int64_t)p->max_bits == INT64_MAX && p->flags == 0);
	p = param("k.max");
	assert_true((int64_t)p->default_bits == 7 && (int64_t)p->min_bits == -10 &&
		    (int64_t)p->max_bits == 10 && p->flags == ARFLEX_PARAM_MUTABLE);
	assert_f64_param("g", 5.0, -DBL_MAX, DBL_MAX, false);
	/* configuration */
	assert_int_equal(c.config.period_ns, 2 * MS);
	assert_int_equal(c.config.deadline_ns, 1500000);
	assert_int_equal(c.config.priority, 80);
	assert_int_equal(c.config.task_type, ARFLEX_TASK_SPORADIC);
	assert_int_equal(c.config.safe_mode, ARFLEX_SAFE_HOLD);
	assert_int_equal(c.config.hb_timeout_ns, 50 * MS);
	assert_int_equal(c.config.orphan_hold_ns, 0);
	assert_int_equal(c.config.cfg_flags, ARFLEX_CFG_MOVES_HARDWARE);
	assert_int_equal(c.config.cpu_mask, 0); /* the DRCR's admission picks a CPU */
	assert_int_equal(unlink(path), 0);
}

/* A service: no timing needed; SCHED_OTHER, memory not locked (as the DRCR sets it). */
static void loads_a_service(void **state)
{
	char path[128];

	(void)state;
	snprintf(path, sizeof(path), "%s/service.xml", dir);
	write_file(path,
		   "<component xmlns='urn:arflex:contract:1' name='svc' version='0.1.0'>"
		   "<implementation executable='svc' task='service'/>"
		   "<resources memory='1MiB'/><criticality>0</criticality>"
		   "<fault restart='temporary' safe='hold'/></component>");
	assert_int_equal(load(path), 0);
	assert_int_equal(c.config.task_type, ARFLEX_TASK_SERVICE);
	assert_int_equal(c.config.priority, 0);
	assert_int_equal(c.config.period_ns, 0);
	assert_int_equal(c.config.cfg_flags, ARFLEX_CFG_NO_MLOCK);
	assert_int_equal(c.noutputs + c.ninputs + c.nparams, 0);
	assert_int_equal(unlink(path), 0);
}

/* A type table entry without a name (a harness's sentinel) matches no <state> type: the
 * reader skipped it for ports but compared it for the state block, a NULL dereference. */
static void a_state_block_passes_over_a_nameless_type_entry(void **state)
{
	static const struct arflex_host_type with_hole[] = {
		{ .name = NULL },
		ARFLEX_HOST_TYPE(SAMPLE),
	};
	char path[128];

	(void)state;
	snprintf(path, sizeof(path), "%s/stateful.xml", dir);
	write_file(path,
		   "<component xmlns='urn:arflex:contract:1' name='svc' version='0.1.0'>"
		   "<implementation executable='svc' task='service'/>"
		   "<resources memory='1MiB'/><criticality>0</criticality>"
		   "<fault restart='temporary' safe='hold'/>"
		   "<state type='arflex.Sample' typeVersion='1.0'/></component>");
	assert_int_equal(arflex_host_load_contract(&c, path, with_hole, 2, err, sizeof(err)), 0);
	assert_true(c.has_state);
	assert_string_equal(c.state.name, "arflex.Sample");
	assert_int_equal(unlink(path), 0);
}

/* The contract is all a harness needs to create an instance. */
static void creates_an_instance_from_a_contract(void **state)
{
	struct arflex_host h;
	struct arflex_host_opts o;
	struct arflex_port vel;
	const struct arflex_port_type want = { "arflex.Sample", 1, 0, 24 };
	char rid[ARFLEX_ID_MAX + 1];
	int kp, sp;

	(void)state;
	th_rid(rid, sizeof(rid), "hc");
	assert_int_equal(load(PI_VELOCITY_XML), 0);
	arflex_host_contract_opts(&c, rid, "pi", &o);
	o.config.cfg_flags |= ARFLEX_CFG_NO_MLOCK | ARFLEX_CFG_NO_DMA_LATENCY;
	assert_int_equal(arflex_host_create(&h, &o), 0);
	assert_int_equal(h.ctl->config.period_ns, 1 * MS);
	assert_int_equal(h.ctl->config.param_count, 3);
	kp = arflex_ctl_param_find(h.ctl, "kp");
	sp = arflex_ctl_param_find(h.ctl, "setpoint");
	assert_true(kp >= 0 && sp >= 0);
	assert_true(arflex_bits_f64(arflex_ctl_param_value(h.ctl, (unsigned)kp)) == 1.0);
	assert_true(arflex_bits_f64(arflex_ctl_param_value(h.ctl, (unsigned)sp)) == 1.0);
	assert_int_equal(arflex_ctl_param_validate(h.ctl, (unsigned)sp, arflex_f64_bits(10.5),
						   true), -ERANGE);
	assert_non_null(arflex_host_output(&h, "velocity"));
	assert_non_null(arflex_host_output(&h, "command"));
	/* what the component's configure will open, as producer: exact type and size */
	assert_int_equal(arflex_port_open(&vel, arflex_host_output_name(&h, "velocity"), true,
					  true, ARFLEX_PORT_STATE, &want), 0);
	arflex_port_close(&vel);
	arflex_host_destroy(&h);
	th_track(rid, "pi");
	th_assert_clean(rid);
}

/* ---- bad inputs ------------------------------------------------------------------------ */

/* A contract of 10 lines; a case replaces the ports (line 4), properties (5), timing (6) or
 * fault (9) line, or gives the whole text. */
struct bad {
	const char *name;
	const char *ports, *props, *timing, *fault, *raw;
	int line;          /* of the error; 0: no position */
	const char *what;  /* in the message */
};

static const struct bad BAD[] = {
	{ "unknown-type", "<out name='y' type='arflex.Nope' typeVersion='1.0' method='state'/>",
	  NULL, NULL, NULL, NULL, 4,
	  "[§6.2] ports/out[y]/@type: unknown port type 'arflex.Nope' (known to this harness: "
	  "arflex.Sample, arflex.SafetyState, arflex.ImageFrame)" },
	{ "duplicate-port", "<out name='y' type='arflex.Sample' typeVersion='1.0' method='state'/>"
	  "<in name='y' type='arflex.Sample' typeVersion='1.0' method='state'/>",
	  NULL, NULL, NULL, NULL, 4, "[§6.1] ports/in[y]: duplicate port 'y'" },
	{ "eval-type", "<in name='t' type='eval.GroundTruth' typeVersion='1.0' method='state'/>",
	  NULL, NULL, NULL, NULL, 4, "evaluation-only type" },
	{ "newer-type", "<out name='y' type='arflex.Sample' typeVersion='1.1' method='state'/>",
	  NULL, NULL, NULL, NULL, 4, "arflex.Sample 1.1 is not compatible with the harness's "
	  "definition 1.0" },
	{ "other-major", "<out name='y' type='arflex.Sample' typeVersion='2.0' method='state'/>",
	  NULL, NULL, NULL, NULL, 4, "not compatible" },
	{ "bad-type-version", "<out name='y' type='arflex.Sample' typeVersion='1' method='state'/>",
	  NULL, NULL, NULL, NULL, 4, "bad type version '1'" },
	{ "method-not-allowed",
	  "<out name='y' type='arflex.Sample' typeVersion='1.0' method='frame' depth='2'/>",
	  NULL, NULL, NULL, NULL, 4, "arflex.Sample does not allow method frame" },
	{ "unknown-method", "<out name='y' type='arflex.Sample' typeVersion='1.0' method='push'/>",
	  NULL, NULL, NULL, NULL, 4, "unknown method 'push'" },
	{ "bad-port-name", "<out name='Y' type='arflex.Sample' typeVersion='1.0' method='state'/>",
	  NULL, NULL, NULL, NULL, 4, "port name 'Y' is not" },
	{ "missing-type", "<out name='y' typeVersion='1.0' method='state'/>",
	  NULL, NULL, NULL, NULL, 4, "out/@type: required attribute missing" },
	{ "stream-no-depth", "<out name='y' type='arflex.Sample' typeVersion='1.0' method='stream'/>",
	  NULL, NULL, NULL, NULL, 4, "ports/out[y]/@depth: required for a stream output" },
	{ "state-depth", "<out name='y' type='arflex.Sample' typeVersion='1.0' method='state' "
	  "depth='2'/>", NULL, NULL, NULL, NULL, 4, "a state output has depth 1, not 2" },
	{ "depth-zero", "<out name='y' type='arflex.Sample' typeVersion='1.0' method='stream' "
	  "depth='0'/>", NULL, NULL, NULL, NULL, 4, "depth 0 not in 1..65536" },
	{ "depth-nan", "<out name='y' type='arflex.Sample' typeVersion='1.0' method='stream' "
	  "depth='6x'/>", NULL, NULL, NULL, NULL, 4, "[§6.4] ports/out[y]/@depth: bad number '6x'" },
	{ "overflow-on-state", "<out name='y' type='arflex.Sample' typeVersion='1.0' "
	  "method='state' overflow='drop-newest'/>", NULL, NULL, NULL, NULL, 4,
	  "only on stream outputs" },
	{ "depth-on-input", "<in name='y' type='arflex.Sample' typeVersion='1.0' method='stream' "
	  "depth='4'/>", NULL, NULL, NULL, NULL, 4, "unknown attribute 'depth'" },
	{ "safety-not-safetystate", "<in name='g' type='arflex.Sample' typeVersion='1.0' "
	  "method='state' safety='true'/>", NULL, NULL, NULL, NULL, 4,
	  "a safety input carries arflex.SafetyState" },
	{ "two-binds", "<in name='x' type='arflex.Sample' typeVersion='1.0' method='state'>"
	  "<bind component='a' port='b'/><bind component='a' port='c'/></in>",
	  NULL, NULL, NULL, NULL, 4, "at most one <bind>" },
	{ "bad-double", NULL, "<property name='g' type='double' default='1.0.0'/>", NULL, NULL,
	  NULL, 5, "[§1.2] properties/property[g]/@default: bad number '1.0.0'" },
	{ "nan-double", NULL, "<property name='g' type='double' default='NaN'/>", NULL, NULL,
	  NULL, 5, "bad number 'NaN'" },
	{ "hex-double", NULL, "<property name='g' type='double' default='0x10'/>", NULL, NULL,
	  NULL, 5, "bad number '0x10'" },
	{ "huge-double", NULL, "<property name='g' type='double' default='1e999'/>", NULL, NULL,
	  NULL, 5, "bad number '1e999'" },
	{ "fraction-int", NULL, "<property name='n' type='int' default='1.5'/>", NULL, NULL,
	  NULL, 5, "bad number '1.5' (a 64-bit integer)" },
	{ "int-overflow", NULL, "<property name='n' type='int' default='9223372036854775808'/>",
	  NULL, NULL, NULL, 5, "bad number '9223372036854775808'" },
	{ "bad-min", NULL, "<property name='g' type='double' default='1' min='zero'/>", NULL,
	  NULL, NULL, 5, "properties/property[g]/@min: bad number 'zero'" },
	{ "default-out-of-range", NULL, "<property name='g' type='double' default='11' min='0' "
	  "max='10'/>", NULL, NULL, NULL, 5, "min <= default <= max does not hold" },
	{ "min-on-bool", NULL, "<property name='b' type='bool' default='true' min='0'/>", NULL,
	  NULL, NULL, 5, "refused on a bool" },
	{ "bad-bool", NULL, "<property name='b' type='bool' default='yes'/>", NULL, NULL, NULL,
	  5, "bad bool 'yes'" },
	{ "unknown-property-type", NULL, "<property name='s' type='string' default='x'/>", NULL,
	  NULL, NULL, 5, "unknown property type 'string'" },
	{ "duplicate-property", NULL, "<property name='g' type='double' default='1'/>"
	  "<property name='g' type='int' default='1'/>", NULL, NULL, NULL, 5,
	  "duplicate property 'g'" },
	{ "bad-duration", NULL, NULL, "<timing period='1.5ms' wcet='50us' priority='60'/>", NULL,
	  NULL, 6, "[§8.1] timing/@period: bad duration '1.5ms'" },
	{ "impossible-timing", NULL, NULL, "<timing period='1ms' wcet='2ms' priority='60'/>",
	  NULL, NULL, 6, "impossible timing" },
	{ "priority-99", NULL, NULL, "<timing period='1ms' wcet='50us' priority='99'/>", NULL,
	  NULL, 6, "bad priority '99'" },
	{ "no-timing", NULL, NULL, "", NULL, NULL, 2, "[§8] timing: required for a periodic" },
	{ "no-fault", NULL, NULL, NULL, "", NULL, 2, "required element <fault> missing" },
	{ "bad-safe", NULL, NULL, NULL, "<fault restart='permanent' safe='off'/>", NULL, 9,
	  "unknown safe output 'off'" },
	{ "heartbeat-shorter-than-period", NULL, NULL,
	  "<timing period='20ms' wcet='50us' priority='60'/>",
	  "<fault restart='permanent' safe='zero' heartbeatTimeout='10ms'/>", NULL, 9,
	  "10ms is shorter than the period" },
	{ "fractional-heartbeat", NULL, NULL, NULL,
	  "<fault restart='permanent' safe='zero' heartbeatTimeout='1500us'/>", NULL, 9,
	  "not whole milliseconds" },
	{ "text-in-ports", "stray", NULL, NULL, NULL, NULL, 4, "text is not allowed in <ports>" },
	{ "unknown-element", "<wire/>", NULL, NULL, NULL, NULL, 4,
	  "[§2.4] ports: unknown element <wire>" },
	{ "unknown-attribute", NULL, NULL, "<timing period='1ms' wcet='50us' priority='60' "
	  "jitter='1us'/>", NULL, NULL, 6, "unknown attribute 'jitter'" },
	{ "element-twice", NULL, NULL, "<timing period='1ms' wcet='50us' priority='60'/>"
	  "<timing period='1ms' wcet='50us' priority='60'/>", NULL, NULL, 6,
	  "<timing> appears twice" },
	{ "too-many-outputs",
	  "<out name='a' type='arflex.Sample' typeVersion='1.0' method='state'/>"
	  "<out name='b' type='arflex.Sample' typeVersion='1.0' method='state'/>"
	  "<out name='c' type='arflex.Sample' typeVersion='1.0' method='state'/>"
	  "<out name='d' type='arflex.Sample' typeVersion='1.0' method='state'/>"
	  "<out name='e' type='arflex.Sample' typeVersion='1.0' method='state'/>"
	  "<out name='f' type='arflex.Sample' typeVersion='1.0' method='state'/>"
	  "<out name='g' type='arflex.Sample' typeVersion='1.0' method='state'/>"
	  "<out name='h' type='arflex.Sample' typeVersion='1.0' method='state'/>"
	  "<out name='i' type='arflex.Sample' typeVersion='1.0' method='state'/>"
	  "<out name='j' type='arflex.Sample' typeVersion='1.0' method='state'/>"
	  "<out name='k' type='arflex.Sample' typeVersion='1.0' method='state'/>"
	  "<out name='l' type='arflex.Sample' typeVersion='1.0' method='state'/>"
	  "<out name='m' type='arflex.Sample' typeVersion='1.0' method='state'/>"
	  "<out name='n' type='arflex.Sample' typeVersion='1.0' method='state'/>"
	  "<out name='o' type='arflex.Sample' typeVersion='1.0' method='state'/>"
	  "<out name='p' type='arflex.Sample' typeVersion='1.0' method='state'/>"
	  "<out name='q' type='arflex.Sample' typeVersion='1.0' method='state'/>",
	  NULL, NULL, NULL, NULL, 4, "more than 16 outputs" },
	{ "moves-hardware-without-guard", NULL, NULL, NULL, NULL,
	  "<component xmlns='urn:arflex:contract:1' name='m' version='1.0.0'>\n"
	  "<implementation executable='m' task='service' movesHardware='true'/>\n"
	  "<resources memory='1MiB'/><criticality>1</criticality>"
	  "<fault restart='permanent' safe='zero'/></component>\n", 1,
	  "declares a safety input" },
	{ "motion-through-unknown", NULL, NULL, NULL, NULL,
	  "<component xmlns='urn:arflex:contract:1' name='m' version='1.0.0'>\n"
	  "<implementation executable='m' task='service' movesHardware='true' motionThrough='robot'/>\n"
	  "<ports><in name='g' type='arflex.SafetyState' typeVersion='1.0' method='state' safety='true'/></ports>"
	  "<resources memory='1MiB'/><criticality>1</criticality>"
	  "<fault restart='permanent' safe='zero'/></component>\n", 2,
	  "[§4.3] implementation/@motionThrough: 'robot' is not where motion goes (device or outputs)" },
	{ "motion-through-without-moves", NULL, NULL, NULL, NULL,
	  "<component xmlns='urn:arflex:contract:1' name='m' version='1.0.0'>\n"
	  "<implementation executable='m' task='service' motionThrough='outputs'/>\n"
	  "<resources memory='1MiB'/><criticality>1</criticality>"
	  "<fault restart='permanent' safe='zero'/></component>\n", 2,
	  "only a component that moves hardware" },
	{ "criticality-101", NULL, NULL, NULL, NULL,
	  "<component xmlns='urn:arflex:contract:1' name='m' version='1.0.0'>\n"
	  "<implementation executable='m' task='service'/>\n"
	  "<resources memory='1MiB'/>\n<criticality>101</criticality>\n"
	  "<fault restart='permanent' safe='zero'/></component>\n", 4,
	  "[§10] criticality: bad number '101'" },
	{ "criticality-long", NULL, NULL, NULL, NULL,
	  "<component xmlns='urn:arflex:contract:1' name='m' version='1.0.0'>\n"
	  "<implementation executable='m' task='service'/><resources memory='1MiB'/>\n"
	  "<criticality>1111111111111111111111111111111111111111111111111111111111111111111111"
	  "</criticality>\n<fault restart='permanent' safe='zero'/></component>\n", 3,
	  "[§10] criticality: bad number '1111111111" },
	{ "wrong-namespace", NULL, NULL, NULL, NULL,
	  "<component xmlns='urn:arflex:contract:2' name='m' version='1.0.0'/>", 1,
	  "[§2.3] component: element <component> is not in the namespace" },
	{ "wrong-root", NULL, NULL, NULL, NULL,
	  "<?xml version='1.0'?>\n<portType xmlns='urn:arflex:contract:1'/>", 2,
	  "the root is <portType>, not <component>" },
	{ "bad-component-name", NULL, NULL, NULL, NULL,
	  "<component xmlns='urn:arflex:contract:1' name='Pi' version='1.0.0'/>", 1,
	  "component/@name: 'Pi' is not" },
	{ "malformed", NULL, NULL, NULL, NULL,
	  "<component xmlns='urn:arflex:contract:1' name='m' version='1.0.0'>\n<ports>\n"
	  "</component>\n", 3, "[§2.1] document: malformed XML: mismatched tag" },
	{ "empty", NULL, NULL, NULL, NULL, "", 1, "malformed XML: no element found" },
	{ "doctype", NULL, NULL, NULL, NULL,
	  "<?xml version='1.0'?>\n<!DOCTYPE component [<!ENTITY a 'aaaa'>]>\n"
	  "<component xmlns='urn:arflex:contract:1' name='m' version='1.0.0'/>", 2,
	  "[§2.2] document: a <!DOCTYPE> is refused" },
	{ "undefined-entity", NULL, NULL, NULL, NULL,
	  "<component xmlns='urn:arflex:contract:1' name='m' version='1.0.0'>\n"
	  "<description>&ent;</description></component>", 2, "malformed XML: undefined entity" },
	{ "processing-instruction", NULL, NULL, NULL, NULL,
	  "<component xmlns='urn:arflex:contract:1' name='m' version='1.0.0'>\n"
	  "<?run rm?></component>", 2, "processing instruction <?run ...?> refused" },
};

static void each_bad_input_is_refused_by_file_and_line(void **state)
{
	static const struct arflex_host_contract zero;
	char path[128], text[4096], prefix[160];

	(void)state;
	for (size_t i = 0; i < sizeof(BAD) / sizeof(BAD[0]); i++) {
		const struct bad *b = &BAD[i];

		snprintf(path, sizeof(path), "%s/%s.xml", dir, b->name);
		if (b->raw)
			snprintf(text, sizeof(text), "%s", b->raw);
		else
			snprintf(text, sizeof(text),
				 "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
				 "<component xmlns=\"urn:arflex:contract:1\" name=\"t\" version=\"1.0.0\">\n"
				 "  <implementation executable=\"t\" task=\"periodic\"/>\n"
				 "  <ports>%s</ports>\n"
				 "  <properties>%s</properties>\n"
				 "  %s\n"
				 "  <resources memory=\"8MiB\"/>\n"
				 "  <criticality>3</criticality>\n"
				 "  %s\n"
				 "</component>\n",
				 b->ports ? b->ports : "<out name='y' type='arflex.Sample' "
				 "typeVersion='1.0' method='state'/>",
				 b->props ? b->props : "",
				 b->timing ? b->timing : "<timing period='1ms' wcet='50us' "
				 "priority='60'/>",
				 b->fault ? b->fault : "<fault restart='permanent' safe='zero'/>");
		write_file(path, text);
		memset(&c, 0xa5, sizeof(c)); /* whatever was there: zeroed on error too */
		err[0] = 'x';
		if (load(path) != -EINVAL || !strstr(err, b->what) ||
		    memcmp(&c, &zero, sizeof(c))) {
			print_error("case %s: got '%s', want '%s'\n", b->name, err, b->what);
			fail();
		}
		snprintf(prefix, sizeof(prefix), "%s:%d:", path, b->line);
		if (strncmp(err, prefix, strlen(prefix))) {
			print_error("case %s: '%s' does not start with '%s'\n", b->name, err,
				    prefix);
			fail();
		}
		assert_int_equal(unlink(path), 0);
	}
	/* the good text of the table loads: the cases fail for their own reason only */
	snprintf(path, sizeof(path), "%s/good.xml", dir);
	write_file(path, "<component xmlns='urn:arflex:contract:1' name='t' version='1.0.0'>"
		   "<implementation executable='t' task='periodic'/><ports><out name='y' "
		   "type='arflex.Sample' typeVersion='1.0' method='state'/></ports>"
		   "<timing period='1ms' wcet='50us' priority='60'/><resources memory='8MiB'/>"
		   "<criticality>3</criticality><fault restart='permanent' safe='zero'/>"
		   "</component>");
	assert_int_equal(load(path), 0);
	assert_int_equal(unlink(path), 0);
}

static void file_errors_are_refused(void **state)
{
	char path[128];

	(void)state;
	snprintf(path, sizeof(path), "%s/none.xml", dir);
	assert_int_equal(load(path), -ENOENT);
	assert_non_null(strstr(err, path));
	assert_non_null(strstr(err, ":0:0: [§2.1] file: cannot open: No such file or directory"));
	assert_int_equal(load(dir), -EINVAL);
	assert_non_null(strstr(err, "not a regular file"));
	/* no type table: every port type is unknown, and said so */
	assert_int_equal(arflex_host_load_contract(&c, PI_VELOCITY_XML, NULL, 0, err,
						   sizeof(err)), -EINVAL);
	assert_non_null(strstr(err, "unknown port type 'arflex.Sample' (known to this harness: "
				    "none)"));
	/* a short error buffer is cut, not overrun */
	assert_int_equal(arflex_host_load_contract(&c, path, TYPES, NTYPES, err, 8), -ENOENT);
	assert_int_equal(strlen(err), 7);
}

static int setup(void **state)
{
	(void)state;
	snprintf(dir, sizeof(dir), "/tmp/arflex-contract-XXXXXX");
	return mkdtemp(dir) ? 0 : -1;
}

static int teardown(void **state)
{
	DIR *d = opendir(dir);
	struct dirent *e;
	char path[384];
	int left = 0;

	(void)state;
	while (d && (e = readdir(d)))
		if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) {
			snprintf(path, sizeof(path), "%s/%s", dir, e->d_name);
			left += unlink(path) == 0;
		}
	if (d)
		closedir(d);
	/* every test removes its files: one left over means a test failed half way */
	return rmdir(dir) || left ? -1 : 0;
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(loads_the_guide_contract),
		cmocka_unit_test(loads_every_kind),
		cmocka_unit_test(loads_a_service),
		cmocka_unit_test(a_state_block_passes_over_a_nameless_type_entry),
		cmocka_unit_test(creates_an_instance_from_a_contract),
		cmocka_unit_test(each_bad_input_is_refused_by_file_and_line),
		cmocka_unit_test(file_errors_are_refused),
	};

	return cmocka_run_group_tests(tests, setup, teardown);
}
