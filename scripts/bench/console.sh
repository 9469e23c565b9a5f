#!/usr/bin/env bash
# Console streaming-load benchmark (./arflex bench console [SECONDS]): the sample pair's RT
# statistics over a window with no browser, then over a window while three headless Chromium
# instances stream live plots from the web console. Prints a table and writes
# target/bench/stream-load.json. Needs the build of ./arflex test. See web-console/README.md.
set -euo pipefail
ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
cd "$ROOT"
exec mvn -B -q -o -Darflex.native.skip=true -pl tests verify \
  -Dtest=none -Dsurefire.failIfNoSpecifiedTests=false -Dit.test=StreamLoadBench \
  -Darflex.bench.seconds="${1:-30}"
