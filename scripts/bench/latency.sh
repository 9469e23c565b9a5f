#!/usr/bin/env bash
# Latency benchmark (issue 5): the paper's Table 1 and beyond, beside cyclictest.
#   ./arflex bench latency [--quick] [--duration S] [--cpu C] [--priority P] [--modes LIST] [--seed N]
# (`scripts/bench/latency.sh --help` lists every option.) Method and how to read the numbers:
# docs/latency.md. Writes target/bench/latency.json and target/bench/latency-<mode>.svg.
#
# Cleanup: the orchestrator (scripts/bench/latency/bench.py) kills what it started, by process
# group; this wrapper forwards Ctrl-C/TERM to it and afterwards removes whatever shared memory
# or message queue of this run's runtime id is left, so nothing stays behind even on failure.
set -uo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
RID="latb$$"
PY_PID=""

sweep() {
  local f
  for f in /dev/shm/arflex."$RID".* /dev/mqueue/arflex."$RID".*; do
    [ -e "$f" ] && rm -f -- "$f" && echo "latency: removed leftover $f" >&2
  done
  return 0
}

on_signal() {
  trap '' INT TERM
  if [ -n "$PY_PID" ] && kill -0 "$PY_PID" 2>/dev/null; then
    kill -TERM "$PY_PID" 2>/dev/null
    wait "$PY_PID" 2>/dev/null
  fi
  sweep
  exit 130
}
trap on_signal INT TERM
trap sweep EXIT

python3 "$ROOT/scripts/bench/latency/bench.py" --rid "$RID" "$@" &
PY_PID=$!
wait "$PY_PID"
status=$?
exit "$status"
