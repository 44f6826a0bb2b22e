#!/usr/bin/env bash
# bench/grid_storage.sh [--device SPEC] [--scene FILE] [--resolution WxH] [--spp N] [--frames K]
#                       [--reps R] [--algorithms "pathtrace raymarch"]
# Grid storage per device (issue 6, item 2): the same scene rendered with renderer.storage "image"
# (3D image, hardware sampler) and "buffer" (float buffer, hand-written trilinear filtering), run
# back to back and alternating (image, buffer, image, buffer, ...) R times after one warm-up of
# each (program build, first launch at the local size), so both see the same machine load.
# pathtrace: kernel seconds of the whole render; raymarch/lobe: median kernel ms per frame of K
# frames. Prints a Markdown table of the medians over the R repetitions and buffer's speed-up
# (image time / buffer time), plus the per-repetition ratios. Not a test: nothing is asserted.
# NARVAL=path/to/narval picks the binary (default build/narval).
set -euo pipefail
cd "$(dirname "$0")/.."
narval=${NARVAL:-build/narval}
device=""
scene=scenes/cloud.json
resolution=160x90
spp=16
frames=5
reps=3
algorithms="pathtrace raymarch"
. bench/bench_common.sh
bench_options "device scene resolution spp frames reps algorithms" "$@"
bench_init

run() { bench_time "$scene" "$1" --set "renderer.storage=$2"; }  # algorithm storage -> seconds

run "${algorithms%% *}" buffer >/dev/null  # also warms up the first algorithm's buffer program
echo "device: $(bench_device "$work/s.json")"
echo "scene: $scene at $resolution (pathtrace: $spp spp; real-time: median of $frames frames); $reps alternating repetitions"
echo
echo "| algorithm | image s (median) | buffer s (median) | image/buffer | per-repetition image/buffer |"
echo "|---|---|---|---|---|"
for alg in $algorithms; do
  bench_ab "$alg" 3 2 run "$alg image" "$alg buffer"
done
