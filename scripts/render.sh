#!/usr/bin/env bash
# scripts/render.sh [SCENE.json] [narval render options...]: set up, then render (default: the
# project's default scene, scenes/cloud.json) into out/.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scene=scenes/cloud.json
if [ $# -gt 0 ] && [[ "$1" != -* ]]; then scene=$1; shift; fi
mkdir -p out
name=$(basename "$scene" .json)
build/narval render "$scene" -o "out/$name.exr" "$@"
echo "images: $(pwd)/out/$name.exr (linear) and $(pwd)/out/$name.png (display)"
