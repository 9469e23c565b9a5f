#!/usr/bin/env python3
"""Per-test failure counts over several runs of a suite (./arflex bench flakes, issue 32).

  flake_table.py DIR [--json FILE]

DIR holds one folder per run (run-1, run-2, ...), each with that run's JUnit XML reports. A run
folder with no report counts as a run in which nothing ran: every test is "not run" there and
the run is named. Prints one row per test case that failed, errored or did not run in at least
one run (with its first message), then the closing line
    flakes: T tests, F failed at least once in N runs
Exit status: 0 when the table could be made (flakes are the finding, not an error), 2 on bad input.
"""
import json
import os
import re
import sys
import xml.etree.ElementTree as ET


def runs_of(d):
    names = [n for n in os.listdir(d) if re.fullmatch(r"run-\d+", n) and os.path.isdir(os.path.join(d, n))]
    return sorted(names, key=lambda n: int(n.split("-")[1]))


def read_run(path):
    """{test id: (outcome, message)} of one run; outcome in ok, failed, skipped."""
    cases = {}
    for f in sorted(os.listdir(path)):
        if not f.endswith(".xml"):
            continue
        try:
            root = ET.parse(os.path.join(path, f)).getroot()
        except ET.ParseError as e:
            cases[f"(unreadable report) {f}"] = ("failed", str(e))
            continue
        for c in root.iter("testcase"):
            tid = f"{c.get('classname', '')}.{c.get('name', '')}"
            outcome, msg = "ok", ""
            for kind in ("failure", "error"):
                el = c.find(kind)
                if el is not None:
                    outcome = "failed"
                    msg = ((el.get("message") or el.text or "").strip().splitlines() or [""])[0][:200]
                    break
            if outcome == "ok" and c.find("skipped") is not None:
                outcome = "skipped"
            cases[tid] = (outcome, msg)
    return cases


def main(argv):
    if not argv or argv[0].startswith("-"):
        print(__doc__.strip(), file=sys.stderr)
        return 2
    d = argv[0]
    js = argv[argv.index("--json") + 1] if "--json" in argv else None
    if not os.path.isdir(d):
        print(f"flake_table: {d}: no such folder", file=sys.stderr)
        return 2
    names = runs_of(d)
    if not names:
        print(f"flake_table: {d}: no run-K folders", file=sys.stderr)
        return 2
    results = {n: read_run(os.path.join(d, n)) for n in names}
    empty = [n for n in names if not results[n]]
    tests = sorted(set().union(*[set(r) for r in results.values()]))
    rows = []
    for t in tests:
        failed = [n for n in names if results[n].get(t, ("not run", ""))[0] in ("failed", "not run")]
        if failed:
            first = next((results[n][t][1] for n in failed if t in results[n] and results[n][t][1]), "not run")
            rows.append({"test": t, "failed_runs": failed, "first_message": first})
    for n in empty:
        print(f"{n}: no report at all (the run did not start or crashed before its first test)")
    if rows:
        w = max(len(r["test"]) for r in rows)
        print(f"{'test'.ljust(w)}  failed  first message")
        for r in rows:
            print(f"{r['test'].ljust(w)}  {len(r['failed_runs'])}/{len(names)}     {r['first_message']}")
    if js:
        with open(js, "w") as f:
            json.dump({"runs": len(names), "tests": len(tests), "empty_runs": empty, "flaky": rows}, f, indent=1)
    print(f"flakes: {len(tests)} tests, {len(rows)} failed at least once in {len(names)} runs")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
