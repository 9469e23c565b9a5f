#!/usr/bin/env bash
# DRCR benchmark (./arflex bench drcr [ROUNDS]): install-to-first-cycle, crash-to-dependents-safe
# and crash-to-Active-again, measured from outside through the ports of the sample pair in a
# real runtime. Prints a table and writes tests/target/bench-drcr.json. See tests/README.md.
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
V=0.1.0-SNAPSHOT
cd "$ROOT"
exec mvn -B -q -o -Darflex.native.skip=true -pl tests test-compile exec:java -Dexec.classpathScope=test \
  -Dexec.mainClass=org.arflex.it.DrcrBench -Dexec.args="${1:-20}" \
  -Darflex.it.runtime="$ROOT/management/runtime/target/arflex-runtime" \
  -Darflex.it.bundles="$ROOT/management/drcr/target/org.arflex.drcr-$V.jar,$ROOT/management/planner/target/org.arflex.planner-$V.jar,$ROOT/contracts/target/org.arflex.contracts-$V.jar" \
  -Darflex.root="$ROOT" \
  -Darflex.it.work="$ROOT/tests/target/it"
