#!/usr/bin/env bash
# Sums every JUnit-style XML report under the given directories (Surefire, Failsafe and
# CTest's --output-junit) and prints one closing line:  N passed, N failed, N skipped
# A tree with no report prints "0 passed, 0 failed" and exits 1, so a run that tested
# nothing cannot pass for a green one. Exit status: 0 when reports exist and none failed.
set -euo pipefail
roots=("$@")
[ ${#roots[@]} -gt 0 ] || roots=(.)

mapfile -t reports < <(find "${roots[@]}" -type f \( -name 'TEST-*.xml' -o -name 'ctest-junit.xml' \) \
  -not -path '*/node_modules/*' 2>/dev/null | sort)

total=0 failed=0 skipped=0
for f in "${reports[@]}"; do
  # Each report has one or more <testsuite ...> start tags carrying the counts; nested
  # <testsuites> wrappers are ignored so nothing is counted twice.
  read -r t fl sk < <(tr '\n\t\r' '   ' < "$f" | grep -o '<testsuite [^>]*>' | awk '
    function attr(s, name,   m) {
      if (match(s, " " name "=\"[0-9]+\"")) { m = substr(s, RSTART, RLENGTH); gsub(/[^0-9]/, "", m); return m + 0 }
      return 0
    }
    { t += attr($0, "tests"); fl += attr($0, "failures") + attr($0, "errors"); sk += attr($0, "skipped") + attr($0, "disabled") }
    END { print t + 0, fl + 0, sk + 0 }')
  total=$((total + t)); failed=$((failed + fl)); skipped=$((skipped + sk))
  if [ "${VERBOSE:-0}" = 1 ]; then printf '%6d tests %4d failed %4d skipped  %s\n' "$t" "$fl" "$sk" "$f"; fi
done

passed=$((total - failed - skipped))
if [ "$failed" -gt 0 ] && command -v python3 >/dev/null; then
  # What failed and why, from the reports themselves: CI keeps only the end of the output.
  python3 - "${reports[@]}" <<'PY' || true
import sys, xml.etree.ElementTree as ET
for f in sys.argv[1:]:
    try:
        root = ET.parse(f).getroot()
    except ET.ParseError as e:
        print(f"FAILED to read {f}: {e}")
        continue
    for case in root.iter("testcase"):
        for kind in ("failure", "error"):
            for el in case.findall(kind):
                msg = (el.get("message") or el.text or "").strip().splitlines()
                out = case.findtext("system-out") or ""
                if len(" ".join(msg)) < 20:  # CTest's "Failed": the test's own FAIL lines
                    msg += [l for l in out.splitlines() if "FAIL" in l][:3]
                text = " | ".join(l.strip() for l in msg[:6])[:1500]
                print(f"FAILED {case.get('classname', '')}.{case.get('name', '')} ({kind}): {text}")
PY
fi
echo "${#reports[@]} test reports read"
if [ "$skipped" -gt 0 ]; then
  echo "${passed} passed, ${failed} failed, ${skipped} skipped"
else
  echo "${passed} passed, ${failed} failed"
fi
[ ${#reports[@]} -gt 0 ] && [ "$total" -gt 0 ] && [ "$failed" -eq 0 ]
