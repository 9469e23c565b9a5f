#!/usr/bin/env bash
# The suite's verdict: sums every JUnit-style report under the given directories (Surefire,
# Failsafe and CTest's --output-junit), checks that every expected suite ran (its report has
# > 0 tests) and that every skip is on tests/suite/skips.allowed with a reason, and prints one
# closing line:  N passed, N failed[, N skipped]. A missing or empty suite and a skip that is
# not allowed each count as a failure and are named. How the expected suites are derived:
# scripts/test_summary.py and docs/decisions/D82-a-suite-that-fails-when-it-should.md.
# Exit status: 0 when reports exist, tests ran and nothing failed.
set -euo pipefail
exec python3 "$(dirname "${BASH_SOURCE[0]}")/test_summary.py" "$@"
