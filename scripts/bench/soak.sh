#!/usr/bin/env bash
# Supervision that never stalls and never leaks (./arflex bench soak [--cycles N] [--kills N]
# [--threads N] [--every N] [--frozen N] [--shared-cpu] [--minutes M]): install -> Felix update -> uninstall cycles of
# sample-scaler and debug-monitor (one worker each) beside an unrelated 1 kHz sample-counter, with
# kill -9 of random churned RT halves spread over the run and, every N-th cycle of a worker (10;
# 0: never), its half SIGSTOPped and the bundle uninstalled; samples the runtime JVM's heap after a full GC, threads
# and fds and the cell's shm/mq/RT processes every N cycles, after a quiet window of the counter
# (workers paused; quiet and churn windows alternate). The counter holds CPU 1 apart from the churn
# and the JVM (docs/latency.md's setup) unless --shared-cpu. Writes target/bench/soak.json; the
# last line is "soak: C cycles, K kills, heap slope S KB/1000 cycles, leaks L, max supervision
# stall X ms". Needs the build of ./arflex test or ./arflex run.
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
cd "$ROOT"
cycles=300 kills=30 threads=2 every= frozen=10 shared=false minutes=0
while [ $# -gt 0 ]; do
  case "$1" in
    --cycles) cycles="${2:?--cycles needs a number}"; shift 2 ;;
    --kills) kills="${2:?--kills needs a number}"; shift 2 ;;
    --threads) threads="${2:?--threads needs a number}"; shift 2 ;;
    --every) every="${2:?--every needs a number}"; shift 2 ;;
    --frozen) frozen="${2:?--frozen needs a number}"; shift 2 ;;
    --shared-cpu) shared=true; shift ;;
    --minutes) minutes="${2:?--minutes needs a number}"; shift 2 ;;
    *) echo "arflex bench soak: unknown option '$1' (--cycles N, --kills N, --threads N, --every N, --frozen N, --shared-cpu, --minutes M)" >&2; exit 2 ;;
  esac
done
for v in "$cycles" "$kills" "$threads" "$frozen" "$minutes" ${every:+"$every"}; do
  [[ "$v" =~ ^[0-9]+$ ]] || { echo "arflex bench soak: '$v' is not a whole number" >&2; exit 2; }
done
mkdir -p target/bench
log=target/bench/soak.log # the whole run, kept for whoever reads a stall; its soak: lines are printed as they come
set +e
mvn -B -o -Darflex.native.skip=true -Darflex.native.tests.skip=true -pl tests verify \
  -Dtest=none -Dsurefire.failIfNoSpecifiedTests=false -Dit.test=SoakBench -Dfailsafe.failIfNoSpecifiedTests=false \
  -Darflex.bench.cycles="$cycles" -Darflex.bench.kills="$kills" -Darflex.bench.threads="$threads" -Darflex.bench.frozen="$frozen" -Darflex.bench.sharedcpu="$shared" -Darflex.bench.minutes="$minutes" \
  ${every:+-Darflex.bench.every="$every"} ${ARFLEX_SOAK_HISTOGRAM:+-Darflex.bench.histogram=true} -Darflex.bench.out="$ROOT/target/bench/soak.json" 2>&1 \
  | tee "$log" | grep --line-buffered -E '^(soak:|JSON:)'
status=${PIPESTATUS[0]}
set -e
if ! grep -q '^soak: [0-9]* cycles, [0-9]* kills' "$log"; then
  tail -40 "$log" >&2
  exit 1
fi
exit $status
