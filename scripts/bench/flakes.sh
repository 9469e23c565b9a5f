#!/usr/bin/env bash
# Flakes measured (issue 32): runs the integration suite N times in a row on this build and
# reports, for every test case, in how many runs it failed. ./arflex bench flakes [N] [--it PATTERN]
#   N            runs (default 3)
#   --it PATTERN only the ITs Failsafe's -Dit.test takes (e.g. 'CellIT,UpdateSetIT'); default: all
# Each run's Failsafe reports are kept in target/flakes/run-K/; the table (scripts/flake_table.py)
# names each test that failed at least once with its first failure message, writes
# target/flakes/flakes.json, and its last line is
#   flakes: T tests, F failed at least once in N runs
# Needs the build of ./arflex test or ./arflex run (the runtime assembly and the cell bundles).
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
cd "$ROOT"
runs=3 pattern=
while [ $# -gt 0 ]; do
  case "$1" in
    --it) pattern="${2:?--it needs a Failsafe test pattern}"; shift 2 ;;
    -h|--help) sed -n '2,11p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) [[ "$1" =~ ^[1-9][0-9]*$ ]] || { echo "arflex bench flakes: '$1' is neither a number of runs nor --it PATTERN" >&2; exit 2; }
       runs=$1; shift ;;
  esac
done
out=target/flakes
rm -rf "$out" && mkdir -p "$out"
for k in $(seq 1 "$runs"); do
  rm -rf tests/target/failsafe-reports
  echo "flakes: run $k of $runs" >&2
  # A failing run is what this measures: go on to the next one.
  mvn -B -q -o -Darflex.native.skip=true -pl tests verify -Dtest=none -Dsurefire.failIfNoSpecifiedTests=false \
      ${pattern:+-Dit.test="$pattern"} -Dit.failIfNoSpecifiedTests=false > "$out/run-$k.log" 2>&1 || true
  mkdir -p "$out/run-$k"
  cp tests/target/failsafe-reports/TEST-*.xml "$out/run-$k/" 2>/dev/null || true
done
exec python3 scripts/flake_table.py "$out" --json "$out/flakes.json"
