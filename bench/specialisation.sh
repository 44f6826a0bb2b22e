#!/usr/bin/env bash
# bench/specialisation.sh [--device SPEC] [--scenes "A.json B.json"] [--resolution WxH] [--spp N]
#                         [--frames K] [--reps R] [--algorithms "pathtrace raymarch"]
# Scene specialisation (issue 6, item 3; host/render/kernel_features.h): each scene rendered with
# the kernel specialised for it (-DPHASE_FIXED=, -DMEDIUM_GREY/CHROMATIC, -DLIGHT_FIXED=,
# -DCAMERA_PINHOLE, as the scene allows) and with the generic kernel (NARVAL_GENERIC=1), after one
# warm-up of each (program build or cache load, first launch), then R alternating repetitions
# (specialised, generic, specialised, ...) so both see the same machine load. pathtrace: kernel
# seconds of the whole render (--stats-json kernel_seconds); raymarch/lobe: median kernel seconds per
# frame of K frames. Prints a Markdown table of the medians and the speed-up (generic / specialised)
# with the per-repetition ratios. Not a test: nothing is asserted.
# NARVAL=path/to/narval picks the binary (default build/narval). The Disney cloud is read from
# NARVAL_DATA_DIR (where scenes/disney_cloud.json looks).
set -euo pipefail
cd "$(dirname "$0")/.."
narval=${NARVAL:-build/narval}
device=""
scenes="scenes/cloud.json scenes/listing_4_1.json scenes/disney_cloud.json"
resolution=160x80
spp=16
frames=5
reps=3
algorithms="pathtrace raymarch"
. bench/bench_common.sh
bench_options "device scenes resolution spp frames reps algorithms" "$@"
bench_init

run() { NARVAL_GENERIC=$3 bench_time "$1" "$2"; }  # scene algorithm generic(0|1) -> seconds

first=${scenes%% *}
run "$first" "${algorithms%% *}" 0 >/dev/null
echo "device: $(bench_device "$work/s.json")"
echo "load average at start: $(cut -d' ' -f1-3 /proc/loadavg) on $(nproc) cores"
echo "$resolution; pathtrace: $spp spp, kernel seconds; real-time: median kernel s per frame of $frames frames;" \
  "$reps alternating repetitions after a warm-up of each program"
echo
echo "| scene | algorithm | specialised s (median) | generic s (median) | speed-up generic/specialised | per-repetition |"
echo "|---|---|---|---|---|---|"
for scene in $scenes; do
  for alg in $algorithms; do
    bench_ab "$scene | $alg" 4 3 run "$scene $alg 0" "$scene $alg 1" inverse
  done
done
echo
echo "load average at end: $(cut -d' ' -f1-3 /proc/loadavg)"
