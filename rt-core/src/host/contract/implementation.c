/* The contract reader's <component> (SPEC 3), <implementation> (SPEC 4), <attribute> (5),
 * <resources> (9) and <update> (12): who the component is and how it is run. */
#include <stdio.h>
#include <string.h>

#include "internal.h"

void arflex_hc_on_component(struct loader *L, const XML_Char **atts)
{
	const char *name = arflex_hc_required(L, atts, "3.1", "component", "name");
	const char *version = name ? arflex_hc_required(L, atts, "3.2", "component", "version")
				   : NULL;

	if (!version)
		return;
	if (!arflex_hc_component_name_ok(name))
		arflex_hc_fail(L, "3.1", "component/@name", "'%s' is not [a-z][a-z0-9-]{0,47}",
			       name);
	else if (!arflex_hc_semver_ok(version))
		arflex_hc_fail(L, "3.2", "component/@version",
			       "'%s' is not a version MAJOR.MINOR.PATCH", version);
	else
		snprintf(L->c->name, sizeof(L->c->name), "%s", name);
}

void arflex_hc_on_implementation(struct loader *L, const XML_Char **atts)
{
	const char *exe = arflex_hc_required(L, atts, "4.1", "implementation", "executable");
	const char *task = exe ? arflex_hc_required(L, atts, "4.2", "implementation", "task")
			       : NULL;

	if (!task)
		return;
	if (!arflex_hc_executable_ok(exe)) {
		arflex_hc_fail(L, "4.1", "implementation/@executable",
			       "'%s' is not a file name [A-Za-z0-9][A-Za-z0-9_.-]{0,63}", exe);
		return;
	}
	snprintf(L->c->executable, sizeof(L->c->executable), "%s", exe);
	if (!strcmp(task, "periodic"))
		L->task = ARFLEX_TASK_PERIODIC;
	else if (!strcmp(task, "sporadic"))
		L->task = ARFLEX_TASK_SPORADIC;
	else if (!strcmp(task, "service"))
		L->task = ARFLEX_TASK_SERVICE;
	else {
		arflex_hc_fail(L, "4.2", "implementation/@task",
			       "unknown task '%s' (periodic, sporadic or service)", task);
		return;
	}
	arflex_hc_opt_bool(L, atts, "4.3", "implementation", "movesHardware", &L->moves_hw);
	const char *through = arflex_hc_attr(atts, "motionThrough");
	if (through && strcmp(through, "device") && strcmp(through, "outputs"))
		arflex_hc_fail(L, "4.3", "implementation/@motionThrough",
			       "'%s' is not where motion goes (device or outputs)", through);
	else if (through && !L->moves_hw)
		arflex_hc_fail(L, "4.3", "implementation/@motionThrough",
			       "only a component that moves hardware (movesHardware=\"true\") says where its motion goes");
}

void arflex_hc_on_attribute(struct loader *L, const XML_Char **atts)
{
	if (!arflex_hc_attr(atts, "name") || !arflex_hc_attr(atts, "value"))
		arflex_hc_fail(L, "5", "attributes/attribute", "name and value are required");
}

void arflex_hc_on_resources(struct loader *L, const XML_Char **atts)
{
	if (!arflex_hc_attr(atts, "memory"))
		arflex_hc_fail(L, "9.2", "resources/@memory", "required attribute missing");
}

void arflex_hc_on_update(struct loader *L, const XML_Char **atts)
{
	if (!arflex_hc_attr(atts, "url") || !arflex_hc_attr(atts, "sha256"))
		arflex_hc_fail(L, "12", "update", "url and sha256 are required");
}
