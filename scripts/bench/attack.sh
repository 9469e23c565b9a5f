#!/usr/bin/env bash
# Security check (./arflex bench attack [--quick]): starts runtimes on this machine and tries,
# against 127.0.0.1 only, the doors an attacker on the same machine has (issue 16): the console's
# cross-site variants (ConsoleAttackBench), every unverified way of bringing code in, forged and
# flooded command queues, squatted names and umask 000 (AttackBench). Prints one line per
# attempt, writes target/bench/attack.json, and ends with "attack: S/N attempts succeeded".
# --quick leaves out the two slow attempts (servers that never answer: ~1 min).
# Needs the build of ./arflex test or ./arflex run.
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
cd "$ROOT"
quick=false
while [ $# -gt 0 ]; do
  case "$1" in
    --quick) quick=true; shift ;;
    *) echo "arflex bench attack: unknown option '$1' (--quick)" >&2; exit 2 ;;
  esac
done
mkdir -p target/bench
log=$(mktemp)
trap 'rm -f "$log"' EXIT
set +e
mvn -B -o -Darflex.native.skip=true -Darflex.native.tests.skip=true -pl tests verify \
  -Dtest=none -Dsurefire.failIfNoSpecifiedTests=false -Dit.test='AttackBench,ConsoleAttackBench' \
  -Dfailsafe.failIfNoSpecifiedTests=false -Darflex.bench.quick="$quick" \
  -Darflex.bench.out.dir="$ROOT/target/bench" >"$log" 2>&1
status=$?
set -e
grep -E '^attack(-part)?: |^JSON: ' "$log" | grep -v '^attack-part: ' || true
parts=$(grep -c '^attack-part: ' "$log" || true)
if [ "$parts" -ne 2 ]; then
  tail -60 "$log" >&2
  echo "arflex bench attack: $parts of 2 parts ran (see above)" >&2
  echo "attack: 1/1 attempts succeeded"
  exit 1
fi
succeeded=0; total=0
while read -r _ _ frac _; do
  succeeded=$((succeeded + ${frac%/*})); total=$((total + ${frac#*/}))
done < <(grep '^attack-part: ' "$log")
{ printf '{"parts":['; sep=""
  for p in runtime console; do
    [ -f "target/bench/attack-$p.json" ] && { printf '%s' "$sep"; tr -d '\n' < "target/bench/attack-$p.json"; sep=","; }
  done
  printf '],"succeeded":%d,"total":%d}\n' "$succeeded" "$total"; } > target/bench/attack.json
echo "JSON: $ROOT/target/bench/attack.json"
echo "attack: $succeeded/$total attempts succeeded"
[ "$status" -eq 0 ] || exit "$status"
