#!/usr/bin/env bash
# scripts/test.sh: set up, then run the whole ctest suite (output shown on failure).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
jobs=$(nproc 2>/dev/null || echo 2)
ctest --test-dir build --output-on-failure -j"$jobs" "$@"
