#!/usr/bin/env bash
# DRCR planner benchmark (./arflex bench planner): full resolve + admission and incremental
# changes on synthetic graphs of 100, 1,000 and 10,000 components. Prints a table and writes
# target/bench/planner.json. See management/planner/README.md.
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
OUT="${ARFLEX_BENCH_OUT:-$ROOT/target/bench/planner.json}"
mkdir -p "$(dirname "$OUT")"
cd "$ROOT"
exec mvn -B -q -o -Darflex.native.skip=true -pl management/planner test-compile exec:java \
  -Dexec.classpathScope=test -Dexec.mainClass=org.arflex.planner.bench.PlannerBench \
  -Dexec.args="$OUT $*"
