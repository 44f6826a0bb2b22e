#!/usr/bin/env bash
# scripts/test.sh [CTEST ARGS]: set up, then run the whole ctest suite (output shown on failure), then
# fuzz the scene and .vol parsers (scripts/fuzz.sh: $NARVAL_FUZZ_SECONDS per target, default 30, 0
# skips). With arguments, ctest gets them and the fuzzing is left out: `scripts/test.sh -L unit` is
# the quick subset (labels: unit, device, render, cli, farm, docs).
# The farm tests use Open Job Description's runner, `openjd` from PyPI's openjd-cli: installed here
# into a virtual environment under build/ (not a build dependency) and named by NARVAL_OPENJD.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
openjd_venv=build/openjd-venv
if [ ! -x "$openjd_venv/bin/openjd" ]; then
  python3 -m venv "$openjd_venv"
  "$openjd_venv/bin/pip" install --quiet --disable-pip-version-check openjd-cli==0.8.0
fi
export NARVAL_OPENJD="$PWD/$openjd_venv/bin/openjd"
jobs=$(nproc 2>/dev/null || echo 2)
ctest --test-dir build --output-on-failure -j"$jobs" "$@"
if [ $# -eq 0 ]; then scripts/fuzz.sh; fi
