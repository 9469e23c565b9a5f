#!/usr/bin/env bash
# No false stops from the machine (./arflex bench stress [--minutes M]): the moving cell as the
# main job runs it, under stress-ng on every core for M minutes (10 by default); counts safe
# stops, hang kills and restarts of healthy components, then checks that a real hang (SIGSTOP of
# the guard) is still caught. Writes target/bench/stress.json; the last line is
# "stress: S safe stops, K hang kills, R restarts in M min; hang caught in H ms", then the force
# guard's trips over the stressed run (each printed with its cause, D77):
# "trips: N in S s under stress-ng".
# Needs the build of ./arflex test or ./arflex run, and stress-ng (scripts/setup.sh installs it).
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
cd "$ROOT"
minutes=10
while [ $# -gt 0 ]; do
  case "$1" in
    --minutes) minutes="${2:?--minutes needs a number}"; shift 2 ;;
    *) echo "arflex bench stress: unknown option '$1' (--minutes M)" >&2; exit 2 ;;
  esac
done
command -v stress-ng >/dev/null || { echo "arflex bench stress: stress-ng is missing (apt-get install stress-ng)" >&2; exit 2; }
log=$(mktemp)
trap 'rm -f "$log"' EXIT
set +e
mvn -B -o -Darflex.native.skip=true -Darflex.native.tests.skip=true -pl tests verify \
  -Dtest=none -Dsurefire.failIfNoSpecifiedTests=false -Dit.test=StressBench -Dfailsafe.failIfNoSpecifiedTests=false \
  -Darflex.bench.minutes="$minutes" -Darflex.bench.out="$ROOT/target/bench/stress.json" >"$log" 2>&1
status=$?
set -e
grep -E '^(stress:|JSON:|trips:)' "$log" || true
if ! grep -q '^stress: [0-9]* safe stops' "$log"; then
  tail -40 "$log" >&2
  exit 1
fi
exit $status
