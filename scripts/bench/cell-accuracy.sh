#!/usr/bin/env bash
# Cell accuracy benchmark (./arflex bench cell-accuracy [POSES]): the main job's cell in an
# evaluation run of the real runtime visits the target poses of arflex-accuracy-bench (24 by
# default) and measures, per pose, the static TRUE tool-centre error with tcp-correction off
# and on and the settling time; also the vision rates in the cell and the age of a pose when it
# is published. Prints a table and writes target/bench/cell-accuracy.json (about 15 s a pose).
# Needs the build of ./arflex test or ./arflex run. See bundles/vision/README.md.
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
cd "$ROOT"
poses="${1:-24}"
case "$poses" in
  ''|*[!0-9]*) echo "cell-accuracy: POSES must be a number in 1..24, not '$poses'" >&2; exit 2 ;;
esac
if [ "$poses" -lt 1 ] || [ "$poses" -gt 24 ]; then
  echo "cell-accuracy: POSES must be in 1..24, not $poses" >&2; exit 2
fi
exec mvn -B -q -o -Darflex.native.skip=true -pl tests verify \
  -Dtest=none -Dsurefire.failIfNoSpecifiedTests=false -Dit.test=CellAccuracyBench \
  -Darflex.bench.poses="$poses"
