#!/usr/bin/env bash
# Cell benchmark (./arflex bench cell [SECONDS] [ROUNDS]): the main job's cell in alternating
# control windows (nothing changes) and change windows (tool swap, vision loss, debug monitor,
# parameter change, back to back); per component cycles, missed periods, overruns, WCET
# overruns and wake-up latency p99/max in each. Prints a table and writes target/bench/cell.json.
# Needs the build of ./arflex test or ./arflex run (the runtime assembly with its cell/). See
# tests/README.md.
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
cd "$ROOT"
exec mvn -B -q -o -Darflex.native.skip=true -pl tests verify \
  -Dtest=none -Dsurefire.failIfNoSpecifiedTests=false -Dit.test=CellChurnBench \
  -Darflex.bench.seconds="${1:-30}" -Darflex.bench.rounds="${2:-3}"
