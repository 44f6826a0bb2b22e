#!/usr/bin/env bash
# scripts/test.sh: set up, then run the whole ctest suite (output shown on failure), then fuzz the
# scene and .vol parsers (scripts/fuzz.sh: $NARVAL_FUZZ_SECONDS per target, default 60, 0 skips).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
jobs=$(nproc 2>/dev/null || echo 2)
ctest --test-dir build --output-on-failure -j"$jobs" "$@"
scripts/fuzz.sh
