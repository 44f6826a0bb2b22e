#!/usr/bin/env bash
# bench/speed_vs_error.sh [SCENE.json ...] [options]
# Speed-versus-error report (issue 4): six methods (pathtrace; raymarch with multiple scattering none,
# octaves or cache; lobe eq7 or corrected), each swept one quality parameter at a time, against a
# cached, converged path-traced reference (default 320x240, 2048 spp) on scenes/cloud, smoke,
# disney_cloud and disney_cloud_front. Writes results.json/.csv (with the multiple-scattering cache's
# build time apart from the frame time), SVG plots with the Pareto front over all methods, the
# frame-budget picks (best real-time configuration within 16 and 100 ms per frame; --budgets-ms) and
# report.md/.html into build/speed_vs_error (or --out DIR). `--methods a,b` and
# `--sweep METHOD.PARAMETER=V1,V2` narrow it; `--quick` is a smoke test (48x24, two values per sweep).
# All options: bench/speed_vs_error.py --help. Not a test: nothing is asserted.
set -euo pipefail
cd "$(dirname "$0")/.."
[ -x build/narval ] || scripts/setup.sh >/dev/null
exec python3 bench/speed_vs_error.py "$@"
