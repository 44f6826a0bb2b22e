#!/usr/bin/env bash
# bench/realtime_tuning.sh [--device SPEC] [--frames K] [--resolution WxH] [--scenes "A.json B.json"]
# How the real-time kernels' automatic settings were chosen (bench/RESULTS.md):
#  1. renderer.lightCache.resolution: both kernels at 16, 32, 64, 96 and 128 cells against exact
#     shadow marching (resolution 0): ms per frame, cache build ms, mean ΔE76 and JND%.
#  2. renderer.lobe.viewSteps: the lobe at 8, 16, 24, 32 and 48 samples per Tr(x0 -> P_i) against
#     100 (what it borrowed from shadowSteps before), cache on.
#  3. minTransmittance (early termination) 1e-4 and 1e-3 against 0, both kernels, cache on.
# Median kernel ms of K frames after the first; ΔE without a display transform (linear, clipped).
set -euo pipefail
cd "$(dirname "$0")/.."
narval=build/narval
device=""
frames=5
resolution=320x240
scenes="scenes/listing_4_1.json scenes/disney_cloud.json scenes/cloud.json scenes/smoke.json"
. bench/bench_common.sh
bench_options "device frames resolution scenes" "$@"
bench_init

# render SCENE ALGORITHM NAME SET... : renders into $work/NAME.exr; prints "ms build_ms cells" (the
# light cache's cells along its longest axis).
render() {
  local scene=$1 algorithm=$2 name=$3
  shift 3
  local sets=()
  for s in "$@"; do sets+=(--set "$s"); done
  # shellcheck disable=SC2086
  "$narval" render "$scene" -o "$work/$name.exr" --algorithm "$algorithm" --resolution "$resolution" \
    --frames "$frames" $device "${sets[@]}" --stats-json "$work/$name.json" >/dev/null 2>&1
  python3 -c "import json,sys; s=json.load(open(sys.argv[1])); print('%.1f %.1f %d' % (s['ms_per_frame']['median'], s['light_cache_ms'], max(s['light_cache_cells'])))" \
    "$work/$name.json"
}
# delta REF TEST: "mean ΔE76 | JND%"
delta() {
  "$narval" compare "$work/$1.exr" "$work/$2.exr" --json | python3 -c \
    "import json,sys; d=json.load(sys.stdin); print('%.3f | %.2f%%' % (d['mean_dE76'], d['jnd76_pct']))"
}

echo "device: $("$narval" devices | sed -n 2p)"
echo "command: bench/realtime_tuning.sh --frames $frames --resolution $resolution"
for scene in $scenes; do
  name=$(basename "$scene" .json)
  missing=$(bench_missing "$scene" | paste -sd, -)
  if [ -n "$missing" ]; then echo; echo "## $name: skipped, $missing absent"; continue; fi
  echo
  echo "## $name ($resolution)"
  echo
  echo "| kernel | setting | ms/frame | cache build ms | mean ΔE76 | JND% |"
  echo "|---|---|---|---|---|---|"
  for algorithm in raymarch lobe; do
    read -r ms _ < <(render "$scene" "$algorithm" "$algorithm-exact" renderer.lightCache.resolution=0)
    echo "| $algorithm | cache off (exact) | $ms | — | 0 | 0% |"
    for cells in 16 32 64 96 128; do
      read -r ms build _ < <(render "$scene" "$algorithm" "$algorithm-$cells" "renderer.lightCache.resolution=$cells")
      echo "| $algorithm | cache $cells | $ms | $build | $(delta "$algorithm-exact" "$algorithm-$cells") |"
    done
    read -r ms _ auto < <(render "$scene" "$algorithm" "$algorithm-noterm" renderer.raymarch.minTransmittance=0 \
      renderer.lobe.minTransmittance=0)
    echo "| $algorithm | cache $auto, minTransmittance 0 | $ms | | 0 | 0% |"
    for eps in 1e-4 1e-3; do
      read -r ms _ < <(render "$scene" "$algorithm" "$algorithm-term$eps" "renderer.raymarch.minTransmittance=$eps" \
        "renderer.lobe.minTransmittance=$eps")
      echo "| $algorithm | cache $auto, minTransmittance $eps | $ms | | $(delta "$algorithm-noterm" "$algorithm-term$eps") |"
    done
  done
  read -r ms _ < <(render "$scene" lobe lobe-view100 renderer.lobe.viewSteps=100)
  echo "| lobe | viewSteps 100 | $ms | | 0 | 0% |"
  for steps in 8 16 24 32 48; do
    read -r ms _ < <(render "$scene" lobe "lobe-view$steps" "renderer.lobe.viewSteps=$steps")
    echo "| lobe | viewSteps $steps | $ms | | $(delta lobe-view100 "lobe-view$steps") |"
  done
done
