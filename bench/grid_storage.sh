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
while [ $# -gt 0 ]; do
  case "$1" in
    --device) device="--device $2"; shift 2 ;;
    --scene) scene=$2; shift 2 ;;
    --resolution) resolution=$2; shift 2 ;;
    --spp) spp=$2; shift 2 ;;
    --frames) frames=$2; shift 2 ;;
    --reps) reps=$2; shift 2 ;;
    --algorithms) algorithms=$2; shift 2 ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
. bench/bench_common.sh
bench_init

run() {  # algorithm storage -> seconds (pathtrace: kernel seconds; others: median kernel s per frame)
  local alg=$1 storage=$2 extra
  if [ "$alg" = pathtrace ]; then extra="--spp $spp"; else extra="--frames $frames"; fi
  # shellcheck disable=SC2086
  "$narval" render "$scene" -o "$work/$alg-$storage.exr" --algorithm "$alg" --resolution "$resolution" $extra \
    $device --set "renderer.storage=$storage" --stats-json "$work/s.json" >/dev/null
  bench_seconds "$work/s.json" "$alg"
}

run "${algorithms%% *}" buffer >/dev/null  # also warms up the first algorithm's buffer program
echo "device: $(bench_device "$work/s.json")"
echo "scene: $scene at $resolution (pathtrace: $spp spp; real-time: median of $frames frames); $reps alternating repetitions"
echo
echo "| algorithm | image s (median) | buffer s (median) | image/buffer | per-repetition image/buffer |"
echo "|---|---|---|---|---|"
for alg in $algorithms; do
  run "$alg" image >/dev/null  # warm-up: build (or cache load) and first launch of each program
  run "$alg" buffer >/dev/null
  image=()
  buffer=()
  for _ in $(seq "$reps"); do
    image+=("$(run "$alg" image)")
    buffer+=("$(run "$alg" buffer)")
  done
  python3 - "$alg" "${image[*]}" "${buffer[*]}" <<'PY'
import statistics, sys
alg, img, buf = sys.argv[1], [float(x) for x in sys.argv[2].split()], [float(x) for x in sys.argv[3].split()]
mi, mb = statistics.median(img), statistics.median(buf)
per = ", ".join("%.2f" % (i / b) for i, b in zip(img, buf))
print(f"| {alg} | {mi:.3f} | {mb:.3f} | {mi / mb:.2f} | {per} |")
PY
done
