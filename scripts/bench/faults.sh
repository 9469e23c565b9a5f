#!/usr/bin/env bash
# Fault benchmark (./arflex bench faults [--quick] [--rounds N] [--seed S] [--jvm-kills N]):
# faults injected from outside into the moving simulated cell (kill -9 and SIGSTOP of RT halves,
# the guard's output header overwritten, a push above the guard's limit, the guard lost for good,
# the motion component in a crash loop, kill -9 of the JVM N times); per scenario pass/fail, time
# to safe, time back to ACTIVE, detection time (fault to the DRCR's log line), leaks. Prints a table, writes target/bench/faults.json; the last line
# is "faults: P/T scenarios pass, leaks L". Needs the build of ./arflex test or ./arflex run.
# See docs/safety.md.
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
cd "$ROOT"
rounds=3
seed=""
jvmkills=""
while [ $# -gt 0 ]; do
  case "$1" in
    --quick) rounds=1; shift ;;
    --rounds) rounds="${2:?--rounds needs a number}"; shift 2 ;;
    --seed) seed="${2:?--seed needs a number}"; shift 2 ;;
    --jvm-kills) jvmkills="${2:?--jvm-kills needs a number}"; shift 2 ;;
    *) echo "arflex bench faults: unknown option '$1' (--quick, --rounds N, --seed S, --jvm-kills N)" >&2; exit 2 ;;
  esac
done
log=$(mktemp)
trap 'rm -f "$log"' EXIT
set +e
mvn -B -o -Darflex.native.skip=true -Darflex.native.tests.skip=true -pl tests verify \
  -Dtest=none -Dsurefire.failIfNoSpecifiedTests=false -Dit.test=FaultBench -Dfailsafe.failIfNoSpecifiedTests=false \
  -Darflex.bench.rounds="$rounds" ${seed:+-Darflex.bench.seed=$seed} ${jvmkills:+-Darflex.bench.jvmkills=$jvmkills} \
  -Darflex.bench.out="$ROOT/target/bench/faults.json" >"$log" 2>&1
status=$?
set -e
grep -E '^(faults:|scenario|S[0-9]|G-|JSON:)' "$log" | grep -v '^faults: .* last line' || true
if ! grep -q '^faults: [0-9]*/[0-9]* scenarios pass' "$log"; then
  tail -40 "$log" >&2
  echo "faults: 0/0 scenarios pass, leaks -1"
  exit 1
fi
grep '^faults: [0-9]*/[0-9]* scenarios pass' "$log" | tail -1 >/dev/null
exit $status
