/* The contract reader's lexical values (SPEC 1.2, 8.1) and names (SPEC 3, 4.1, 6.1, 6.2, 7.1):
 * pure functions of a string, no reporting. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"

bool arflex_hc_xml_space(char ch)
{
	return ch == ' ' || ch == '\t' || ch == '\n' || ch == '\r';
}

/* Copies @s without surrounding white space into @buf; false if it does not fit. */
static bool trimmed(const char *s, char *buf, size_t size)
{
	size_t n;

	while (arflex_hc_xml_space(*s))
		s++;
	n = strlen(s);
	while (n && arflex_hc_xml_space(s[n - 1]))
		n--;
	if (n >= size)
		return false;
	memcpy(buf, s, n);
	buf[n] = '\0';
	return true;
}

static size_t digits(const char *s)
{
	size_t n = 0;

	while (s[n] >= '0' && s[n] <= '9')
		n++;
	return n;
}

/* [+-]?([0-9]+(\.[0-9]*)?|\.[0-9]+)([eE][+-]?[0-9]{1,3})?, finite. */
bool arflex_hc_parse_decimal(const char *s, double *out)
{
	char buf[128], *end;
	const char *q;
	size_t n, f = 0;
	double d;

	if (!trimmed(s, buf, sizeof(buf)))
		return false;
	q = buf + (buf[0] == '+' || buf[0] == '-');
	n = digits(q);
	q += n;
	if (*q == '.') {
		f = digits(q + 1);
		q += 1 + f;
	}
	if (n == 0 && f == 0)
		return false;
	if (*q == 'e' || *q == 'E') {
		q++;
		q += *q == '+' || *q == '-';
		n = digits(q);
		if (n < 1 || n > 3)
			return false;
		q += n;
	}
	if (*q)
		return false;
	errno = 0;
	d = strtod(buf, &end);
	if (*end || !isfinite(d))
		return false;
	*out = d;
	return true;
}

/* [+-]?[0-9]{1,19} in int64 range. */
bool arflex_hc_parse_int(const char *s, int64_t *out)
{
	char buf[64], *end;
	const char *q;
	size_t n;
	long long v;

	if (!trimmed(s, buf, sizeof(buf)))
		return false;
	q = buf + (buf[0] == '+' || buf[0] == '-');
	n = digits(q);
	if (n < 1 || n > 19 || q[n])
		return false;
	errno = 0;
	v = strtoll(buf, &end, 10);
	if (errno || *end)
		return false;
	*out = v;
	return true;
}

bool arflex_hc_parse_bool(const char *s, bool *out)
{
	if (!strcmp(s, "true"))
		*out = true;
	else if (!strcmp(s, "false"))
		*out = false;
	else
		return false;
	return true;
}

/* [0-9]{1,15}(ns|us|ms|s) in ns, without overflow. */
bool arflex_hc_parse_duration(const char *s, uint64_t *out)
{
	char buf[64];
	size_t n;
	uint64_t v, mul;

	if (!trimmed(s, buf, sizeof(buf)))
		return false;
	n = digits(buf);
	if (n < 1 || n > 15)
		return false;
	if (!strcmp(buf + n, "ns"))
		mul = 1;
	else if (!strcmp(buf + n, "us"))
		mul = 1000;
	else if (!strcmp(buf + n, "ms"))
		mul = MS;
	else if (!strcmp(buf + n, "s"))
		mul = SEC;
	else
		return false;
	v = strtoull(buf, NULL, 10);
	if (v > INT64_MAX / mul)
		return false;
	*out = v * mul;
	return true;
}

static bool is_lower(char ch) { return ch >= 'a' && ch <= 'z'; }
static bool is_upper(char ch) { return ch >= 'A' && ch <= 'Z'; }
static bool is_digit(char ch) { return ch >= '0' && ch <= '9'; }

/* A port type's version (SPEC 6.2): MAJOR.MINOR, each at most 5 digits. */
bool arflex_hc_parse_type_version(const char *s, unsigned *major, unsigned *minor)
{
	int n = 0;

	return sscanf(s, "%5u.%5u%n", major, minor, &n) == 2 && !s[n] && is_digit(s[0]) &&
	       is_digit(s[strlen(s) - 1]);
}

/* @s is one character of @first then at most @max - 1 of @rest. */
static bool name_ok(const char *s, bool (*first)(char), bool (*rest)(char), size_t max)
{
	size_t n;

	if (!first(s[0]))
		return false;
	for (n = 1; s[n]; n++)
		if (n >= max || !rest(s[n]))
			return false;
	return true;
}

static bool component_first(char ch) { return is_lower(ch); }
static bool component_rest(char ch) { return is_lower(ch) || is_digit(ch) || ch == '-'; }
static bool port_rest(char ch) { return is_lower(ch) || is_digit(ch) || ch == '_'; }
static bool prop_rest(char ch) { return port_rest(ch) || ch == '.'; }
static bool exe_first(char ch) { return is_lower(ch) || is_upper(ch) || is_digit(ch); }
static bool exe_rest(char ch) { return exe_first(ch) || ch == '_' || ch == '.' || ch == '-'; }

bool arflex_hc_component_name_ok(const char *s)
{
	return name_ok(s, component_first, component_rest, 48);
}

bool arflex_hc_executable_ok(const char *s)
{
	return name_ok(s, exe_first, exe_rest, 64);
}

bool arflex_hc_port_name_ok(const char *s)
{
	return name_ok(s, component_first, port_rest, 32);
}

bool arflex_hc_property_name_ok(const char *s)
{
	return name_ok(s, component_first, prop_rest, 31);
}

/* MAJOR.MINOR.PATCH, no leading zeros, optional -pre.release (SPEC 3.2). */
bool arflex_hc_semver_ok(const char *s)
{
	for (int part = 0; part < 3; part++) {
		size_t n = digits(s);

		if (n < 1 || n > 9 || (n > 1 && s[0] == '0'))
			return false;
		s += n;
		if (part < 2 && *s++ != '.')
			return false;
	}
	if (!*s)
		return true;
	if (*s++ != '-' || !*s)
		return false;
	for (; *s; s++)
		if (!exe_first(*s) && *s != '-' && !(*s == '.' && s[1] && s[1] != '.'))
			return false;
	return true;
}
