#!/usr/bin/env python3
"""The suite's verdict (docs/decisions/D82-a-suite-that-fails-when-it-should.md).

Reads every JUnit-style report under the given roots (Surefire, Failsafe and CTest's
--output-junit) and checks them against what the roots say should have run:

  Java   every class under a src/test/java folder whose file name Surefire's or Failsafe's
         default includes take (Test*, *Test, *Tests, *TestCase; IT*, *IT, *ITCase), that is
         not abstract and declares a test method, needs a TEST-<class>.xml with > 0 tests.
         Benchmarks (*Bench) match no include and are not expected.
  CTest  every line "<build dir> <name prefix>" of tests/suite/ctest.expected needs the build
         dir's ctest-junit.xml with a test whose name starts with the prefix; and every test
         `ctest -N` lists in that build dir must be in its report.
  Skips  every skipped test must match a line "<pattern> <reason>" of tests/suite/skips.allowed
         (fnmatch pattern on "<class>.<test>" for Java, the test name for CTest).

A missing or empty suite, a test missing from a CTest report and a skip not allowed each count
as one failure and are named. The closing line is as before:  N passed, N failed[, N skipped]
Exit status 0 when reports exist, more than 0 tests ran and nothing failed.

  scripts/test-summary.sh [ROOT...]          (ROOT defaults to .)
  scripts/test-summary.sh --list-expected [ROOT...]   prints the expected suites and stops
"""
import fnmatch
import os
import re
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET

PRUNE = {"node_modules", "target", ".git", "build"}
INCLUDES = [re.compile(p) for p in (r"Test.*", r".*Test", r".*Tests", r".*TestCase",
                                    r"IT.*", r".*IT", r".*ITCase")]
TEST_METHOD = re.compile(r"@(Test|ParameterizedTest|RepeatedTest|TestFactory|TestTemplate|FuzzTest|Property)\b")
PACKAGE = re.compile(r"^\s*package\s+([\w.]+)\s*;", re.M)
CTEST_EXPECTED = os.path.join("tests", "suite", "ctest.expected")
SKIPS_ALLOWED = os.path.join("tests", "suite", "skips.allowed")


def walk(root):
    for d, dirs, files in os.walk(root):
        dirs[:] = sorted(x for x in dirs if x not in PRUNE)
        yield d, sorted(files)


def expected_java(root):
    """{fqcn: source path} of every class Surefire or Failsafe would run from this tree."""
    out = {}
    for d, files in walk(root):
        if os.sep + os.path.join("src", "test", "java") not in d + os.sep:
            continue
        for f in files:
            if not f.endswith(".java") or not any(p.fullmatch(f[:-5]) for p in INCLUDES):
                continue
            path = os.path.join(d, f)
            with open(path, encoding="utf-8", errors="replace") as fh:
                src = fh.read()
            abstract = re.search(r"^[ \t]*(?:\w+[ \t]+)*abstract[ \t]+(?:\w+[ \t]+)*class[ \t]+" + re.escape(f[:-5]) + r"\b",
                                 src, re.M)
            if abstract or not TEST_METHOD.search(src):
                continue
            m = PACKAGE.search(src)
            out[(m.group(1) + "." if m else "") + f[:-5]] = path
    return out


def read_lines(path):
    """(line number, fields) of the non-comment lines of a list file; none when it is absent."""
    if not os.path.isfile(path):
        return []
    rows = []
    with open(path, encoding="utf-8") as fh:
        for n, line in enumerate(fh, 1):
            line = line.strip()
            if line and not line.startswith("#"):
                rows.append((n, line.split(None, 1)))
    return rows


def find_reports(roots):
    reports = []
    for root in roots:
        for d, _, files in os.walk(root):
            if "node_modules" in d.split(os.sep) or os.sep + ".git" in d:
                continue
            reports += [os.path.join(d, f) for f in files
                        if (f.startswith("TEST-") and f.endswith(".xml")) or f == "ctest-junit.xml"]
    return sorted(reports)


def num(el, name):
    v = el.get(name) or "0"
    return int(v) if v.isdigit() else 0


def case_id(case):
    cls, name = case.get("classname") or "", case.get("name") or ""
    return f"{cls}.{name}" if cls and cls != name else name


def ctest_names(build_dir):
    """The tests CTest knows in a build dir, or None when it cannot be asked."""
    if not os.path.isfile(os.path.join(build_dir, "CTestTestfile.cmake")) or not shutil.which("ctest"):
        return None
    r = subprocess.run(["ctest", "-N"], cwd=build_dir, capture_output=True, text=True)
    if r.returncode != 0:
        return None
    return [m.group(1) for m in re.finditer(r"^\s*Test\s+#\d+:\s+(\S+)\s*$", r.stdout, re.M)]


def main(argv):
    list_only = bool(argv) and argv[0] == "--list-expected"
    roots = (argv[1:] if list_only else argv) or ["."]
    verbose = os.environ.get("VERBOSE") == "1"
    problems = []  # one line each, each one failure

    java = {}
    ctest = {}     # abs build dir -> [(prefix, where)]
    allowed = []   # (pattern, reason)
    for root in roots:
        java.update(expected_java(root))
        for n, fields in read_lines(os.path.join(root, CTEST_EXPECTED)):
            where = f"{os.path.join(root, CTEST_EXPECTED)}:{n}"
            if len(fields) != 2 or len(fields[1].split()) != 1:
                problems.append(f"BAD LINE {where}: want '<build dir> <test name prefix>'")
                continue
            ctest.setdefault(os.path.normpath(os.path.join(root, fields[0])), []).append((fields[1], where))
        for n, fields in read_lines(os.path.join(root, SKIPS_ALLOWED)):
            if len(fields) != 2:
                problems.append(f"BAD LINE {os.path.join(root, SKIPS_ALLOWED)}:{n}: "
                                "want '<test pattern> <reason>' (a skip needs its reason)")
                continue
            allowed.append((fields[0], fields[1]))

    if list_only:
        for cls in sorted(java):
            print(f"java {cls}")
        for d in sorted(ctest):
            for prefix, _ in ctest[d]:
                print(f"ctest {d} {prefix}")
        return 0

    reports = find_reports(roots)
    total = failed = skipped = 0
    per_class = {}         # fqcn -> tests in its TEST-<fqcn>.xml reports
    ctest_cases = {}       # abs build dir -> set of test names in its ctest-junit.xml
    failures = []
    skips = []             # (id, message)
    for f in reports:
        try:
            root_el = ET.parse(f).getroot()
        except ET.ParseError as e:
            problems.append(f"UNREADABLE {f}: {e}")
            continue
        suites = [root_el] if root_el.tag == "testsuite" else list(root_el.iter("testsuite"))
        t = sum(num(s, "tests") for s in suites)
        fl = sum(num(s, "failures") + num(s, "errors") for s in suites)
        sk = sum(num(s, "skipped") + num(s, "disabled") for s in suites)
        total, failed, skipped = total + t, failed + fl, skipped + sk
        if verbose:
            print(f"{t:6d} tests {fl:4d} failed {sk:4d} skipped  {f}")
        name = os.path.basename(f)
        if name == "ctest-junit.xml":
            ctest_cases.setdefault(os.path.normpath(os.path.abspath(os.path.dirname(f))), set()).update(
                c.get("name") or "" for c in root_el.iter("testcase"))
        else:
            cls = name[len("TEST-"):-len(".xml")]
            per_class[cls] = per_class.get(cls, 0) + t
        for case in root_el.iter("testcase"):
            for kind in ("failure", "error"):
                for el in case.findall(kind):
                    failures.append((case, kind, el))
            sk_el = case.find("skipped")
            if sk_el is not None or case.get("status") in ("notrun", "disabled"):
                msg = (sk_el.get("message") if sk_el is not None else None) or case.get("status") or ""
                skips.append((case_id(case), msg.strip().splitlines()[0] if msg.strip() else ""))

    for cls in sorted(java):
        if cls not in per_class:
            problems.append(f"MISSING {cls}: no TEST-{cls}.xml report ({java[cls]})")
        elif per_class[cls] == 0:
            problems.append(f"EMPTY {cls}: its report holds 0 tests ({java[cls]})")

    for d in sorted(ctest):
        absd = os.path.normpath(os.path.abspath(d))
        have = ctest_cases.get(absd)
        if have is None:
            problems.append(f"MISSING ctest {d}: no {os.path.join(d, 'ctest-junit.xml')} (expected by {ctest[d][0][1]})")
            continue
        if not have:
            problems.append(f"EMPTY ctest {d}: its ctest-junit.xml holds 0 tests")
            continue
        for prefix, where in ctest[d]:
            if not any(n.startswith(prefix) for n in have):
                problems.append(f"MISSING ctest {prefix}* in {d}: no such test in its report ({where})")
        known = ctest_names(d)
        for n in known or []:
            if n not in have:
                problems.append(f"MISSING ctest {n} in {d}: `ctest -N` lists it, its report does not")

    for sid, msg in skips:
        rule = next((r for p, r in allowed if fnmatch.fnmatchcase(sid, p)), None)
        if rule is None:
            problems.append(f"SKIPPED, NOT ALLOWED {sid}: {msg} (allow it in {SKIPS_ALLOWED} with a reason, or fix it)")
        else:
            print(f"skipped (allowed: {rule}) {sid}: {msg}")

    for case, kind, el in failures:
        msg = (el.get("message") or el.text or "").strip().splitlines()
        out = case.findtext("system-out") or ""
        if len(" ".join(msg)) < 20:  # CTest's "Failed": the test's own FAIL lines
            msg += [l for l in out.splitlines() if "FAIL" in l][:3]
        text = " | ".join(l.strip() for l in msg[:6])[:1500]
        print(f"FAILED {case.get('classname', '')}.{case.get('name', '')} ({kind}): {text}")
    for p in problems:
        print(p)

    failed += len(problems)
    passed = total - (failed - len(problems)) - skipped
    print(f"{len(reports)} test reports read")
    print(f"{passed} passed, {failed} failed" + (f", {skipped} skipped" if skipped else ""))
    return 0 if reports and total > 0 and failed == 0 else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
