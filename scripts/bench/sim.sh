#!/usr/bin/env bash
# ./arflex bench sim: the sim-robot RT half's period latency with and without a sim-camera
# rendering 640x480 at 30 Hz beside it (simulator/README.md, "Components: benchmark"), then
# the simulator library's own benchmark (physics steps/s, frames/s per camera).
#   scripts/bench/sim.sh [--seconds S] [--priority P] [other arflex-sim-comp-bench options]
# Uses the Maven-built native tree (target/native) or ARFLEX_NATIVE_DIR; builds the two
# benchmark targets there if they are missing. JSON goes to target/bench/.
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
BUILD=${ARFLEX_NATIVE_DIR:-$ROOT/target/native}
OUT=$ROOT/target/bench
if [ ! -x "$BUILD/bin/arflex-sim-comp-bench" ] || [ ! -x "$BUILD/bin/arflex-sim-bench" ]; then
  [ -f "$BUILD/build.ninja" ] || cmake -S "$ROOT" -B "$BUILD" -G Ninja >/dev/null
  cmake --build "$BUILD" -j2 --target arflex-sim-comp-bench arflex-sim-bench sim-robot sim-camera
fi
mkdir -p "$OUT"
"$BUILD/bin/arflex-sim-comp-bench" --json "$OUT/sim-comp.json" "$@"
"$BUILD/bin/arflex-sim-bench" "$OUT/sim.json"
