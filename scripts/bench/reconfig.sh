#!/usr/bin/env bash
# Reconfiguration of the moving cell (./arflex bench reconfig [--sets N] [--mlock]): issue #19's change sets
# on the moving simulated arm, each example N times (3) in one runtime: teach replaces trajectory
# and trajectory replaces teach again, tcp-correction updated to 1.0.1 and back to 1.0.0, a faulty
# version (SIGSEGV 250 ms after its spawn) rolled back. Per set: preparation time, the switch's
# actor turn, sim-robot's latency and overruns around the switch against a quiet window before it,
# released cycles it did not run (against the quiet windows' rate), the largest step of the robot's
# reference per source cycle, safe stops, operator resets. Prints a table, writes
# target/bench/reconfig.json; the last line is "reconfig: S sets, missed cycles M, safe stops X,
# resets R, max jump J rad". --mlock: the RT halves lock their memory (mlockall, as outside the
# tests; the tests' runtime passes arflex.nomlock). docs/DECISIONS.md D40, docs/reconfig.md. Needs the build of ./arflex test or ./arflex run.
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
cd "$ROOT"
sets=3
mlock=false
shield=""
poll=""
while [ $# -gt 0 ]; do
  case "$1" in
    --sets) sets="${2:?--sets needs a number}"; shift 2 ;;
    --mlock) mlock=true; shift ;;
    --shield) shield="${2:?--shield needs a CPU list}"; shift 2 ;;
    --poll) poll=--poll; shift ;;
    *) echo "arflex bench reconfig: unknown option '$1' (--sets N, --mlock, --shield CPUS, --poll)" >&2; exit 2 ;;
  esac
done
[[ "$sets" =~ ^[1-9][0-9]*$ ]] || { echo "arflex bench reconfig: --sets '$sets' is not a whole number above 0" >&2; exit 2; }
[ -n "$shield" ] || [ -z "$poll" ] || { echo "arflex bench reconfig: --poll needs --shield" >&2; exit 2; }
log=$(mktemp)
trap 'rm -f "$log"' EXIT
jvmcpus=""
if [ -n "$shield" ]; then
  # the runtime's JVM on the CPUs the shield leaves to the rest of the machine
  jvmcpus=$(bash scripts/rt-shield.sh rest --cpus "$shield")
  bash scripts/rt-shield.sh on --cpus "$shield" --keep $$ $poll >&2
  trap 'rm -f "$log"; bash scripts/rt-shield.sh off >&2' EXIT
fi
set +e
mvn -B -o -Darflex.native.skip=true -Darflex.native.tests.skip=true -pl tests verify \
  -Dtest=none -Dsurefire.failIfNoSpecifiedTests=false -Dit.test=ReconfigBench -Dfailsafe.failIfNoSpecifiedTests=false \
  -Darflex.bench.sets="$sets" -Darflex.it.mlock="$mlock" -Darflex.it.jvmcpus="$jvmcpus" -Darflex.bench.shield="$shield" -Darflex.bench.poll="$([ -n "$poll" ] && echo true || echo false)" -Darflex.bench.out="$ROOT/target/bench/reconfig.json" >"$log" 2>&1
status=$?
set -e
if [ -n "$shield" ]; then
  # off before the table: the last line stays the bench's
  bash scripts/rt-shield.sh off >&2
  trap 'rm -f "$log"' EXIT
fi
grep -E '^(reconfig:|JSON:)' "$log" | grep -v '^reconfig: [0-9]* sets, ' || true
if ! grep -q '^reconfig: [0-9]* sets, missed cycles' "$log"; then
  tail -40 "$log" >&2
  exit 1
fi
[ -z "$shield" ] || echo "reconfig: every other process kept off CPUs $shield (scripts/rt-shield.sh)"
grep '^reconfig: [0-9]* sets, missed cycles' "$log" | tail -1
exit $status
