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
# NARVAL_DATA_DIR (default ../shared/data/volumes, see scenes/disney_cloud.json).
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
while [ $# -gt 0 ]; do
  case "$1" in
    --device) device="--device $2"; shift 2 ;;
    --scenes) scenes=$2; shift 2 ;;
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

run() {  # scene algorithm generic(0|1) -> seconds
  local scene=$1 alg=$2 generic=$3 extra
  if [ "$alg" = pathtrace ]; then extra="--spp $spp"; else extra="--frames $frames"; fi
  # shellcheck disable=SC2086
  NARVAL_GENERIC=$generic "$narval" render "$scene" -o "$work/out.exr" --algorithm "$alg" \
    --resolution "$resolution" $extra $device --stats-json "$work/s.json" >/dev/null
  bench_seconds "$work/s.json" "$alg"
}

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
    run "$scene" "$alg" 0 >/dev/null  # warm-up: build (or cache load) and first launch
    run "$scene" "$alg" 1 >/dev/null
    spec=()
    gen=()
    for _ in $(seq "$reps"); do
      spec+=("$(run "$scene" "$alg" 0)")
      gen+=("$(run "$scene" "$alg" 1)")
    done
    python3 - "$scene" "$alg" "${spec[*]}" "${gen[*]}" <<'PY'
import statistics, sys
scene, alg = sys.argv[1], sys.argv[2]
sp, ge = [float(x) for x in sys.argv[3].split()], [float(x) for x in sys.argv[4].split()]
ms, mg = statistics.median(sp), statistics.median(ge)
per = ", ".join("%.3f" % (g / s) for s, g in zip(sp, ge))
print(f"| {scene} | {alg} | {ms:.4f} | {mg:.4f} | {mg / ms:.3f} | {per} |")
PY
  done
done
echo
echo "load average at end: $(cut -d' ' -f1-3 /proc/loadavg)"
