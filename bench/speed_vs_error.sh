#!/usr/bin/env bash
# bench/speed_vs_error.sh [SCENE.json ...] [options]
# Speed-versus-error report (issue 4): every algorithm across its quality parameters against a
# cached, converged path-traced reference; results.json/.csv, SVG plots with the Pareto front and
# report.md/.html in build/speed_vs_error (or --out DIR). `--quick` is a smoke test (48x24).
# All options: bench/speed_vs_error.py --help. Not a test: nothing is asserted.
set -euo pipefail
cd "$(dirname "$0")/.."
[ -x build/narval ] || scripts/setup.sh >/dev/null
exec python3 bench/speed_vs_error.py "$@"
