#!/usr/bin/env bash
# IPC benchmark of rt-core (./arflex bench ipc): state-port one-way latency against a raw
# shared-memory spin handshake, and mailbox round trip against a raw POSIX mq round trip, two
# processes pinned to different CPUs. Prints a table and writes target/bench/ipc.json.
# Extra arguments go to arflex-bench-ipc (e.g. --samples 20000 --priority 80); see
# rt-core/bench/README.md.
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
# ARFLEX_NATIVE_BIN overrides where the executables are (default: the Maven native build).
EXE="${ARFLEX_NATIVE_BIN:-$ROOT/target/native/bin}/arflex-bench-ipc"
OUT="${ARFLEX_BENCH_OUT:-$ROOT/target/bench/ipc.json}"
if [ ! -x "$EXE" ]; then
  echo "bench ipc: $EXE not found; build first (./arflex test, or mvn install)" >&2
  exit 1
fi
mkdir -p "$(dirname "$OUT")"
exec "$EXE" --json "$OUT" "$@"
