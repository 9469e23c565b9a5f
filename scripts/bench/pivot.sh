#!/usr/bin/env bash
# ./arflex bench pivot: the tool (TCP) pivot calibration of the simulated cell from camera
# images alone (bundles/vision/README.md, "Tool (TCP) calibration", D83): 24 orientations of
# the tool about a fixed tip point, the marker pose of each from the four cameras, the pivot
# solve; prints the recovered TCP against the simulator's TRUE one (scoring only) and writes
# the tool calibration file to target/bench/tool-1.cal (copy it to $ARFLEX_DATA_DIR/tool-1.cal
# for vision-rt, or pass --out there). Extra arguments go to arflex-pivot-calibration.
#   scripts/bench/pivot.sh [--poses N] [--frames K] [--tilt-deg D] [--pivot X,Y,Z] [--unweighted] [--check TOL_MM]
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
OUT=$ROOT/target/bench
. "$ROOT/scripts/native-target.sh"
BIN=$(native_target arflex-pivot-calibration)
mkdir -p "$OUT"
exec "$BIN" --out "$OUT/tool-1.cal" "$@"
