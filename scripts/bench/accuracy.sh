#!/usr/bin/env bash
# ./arflex bench accuracy: the vision-corrected accuracy study (issue 7, bundles/vision/README.md):
# 24 target poses, static TCP error against the simulator's ground truth with the outer
# correction off and on; payload 0/100/210 kg, one and two cameras blocked, nominal tool
# offset; vision frames and poses per second, frame-to-correction latency.
#   scripts/bench/accuracy.sh [--quick] [--poses N] [--noise SIGMA] [--blur SIGMA]
#                             [--period-ms P] [--width W --height H] [--no-refine]
#                             [--with-orientation] [--outlier-px PX] [--only INDEX] [--trace]
#                             [--calib-frames N] [--calib-at-home] [--average K] [--diag] [--no-loop] [--cameras LIST]
#                             [--tool-calibration FILE]   (a run with the pivot-calibrated TCP: ./arflex bench pivot)
# Uses the Maven-built native tree (target/native) or ARFLEX_NATIVE_DIR; builds the benchmark
# there if it is missing. JSON goes to target/bench/accuracy.json. Takes 10-30 minutes on a
# loaded 2-core machine (software rendering dominates); --quick runs only payload 0.
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
OUT=$ROOT/target/bench
. "$ROOT/scripts/native-target.sh"
BIN=$(native_target arflex-accuracy-bench)
mkdir -p "$OUT"
exec "$BIN" --json "$OUT/accuracy.json" "$@"
