#!/usr/bin/env bash
# bench/emission_cost.sh [--device SPEC] [--resolution WxH] [--spp N] [--frames K] [--reps R]
# What emission costs (kernels/shared/emission.h):
# - on the fire (scenes/fire.json): the scene as shipped against the same scene with its emission
#   object removed (the kernel then has no emission code: -DEMISSION is not set);
# - on scenes that do not emit: their own kernels (no emission code) against kernels built with
#   emission on (the same scene with "emission": {"color": [0, 0, 0]}: -DEMISSION, every tentative
#   collision and march step evaluating σa·Le = 0), i.e. what the specialisation saves.
# After one warm-up of each, R alternating repetitions. pathtrace: kernel seconds of the render;
# raymarch/lobe: median kernel seconds per frame of K frames. Prints a Markdown table of medians
# and the ratio (with / without emission code). Not a test: nothing is asserted.
# NARVAL=path/to/narval picks the binary (default build/narval); real grids from NARVAL_DATA_DIR.
set -euo pipefail
cd "$(dirname "$0")/.."
narval=${NARVAL:-build/narval}
device=""
resolution=160x120
spp=16
frames=5
reps=3
. bench/bench_common.sh
bench_options "device resolution spp frames reps" "$@"
bench_init

# The fire without its emission object, beside the original (so its relative volume path holds).
python3 - scenes/fire.json scenes/.fire_no_emission.json <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
for m in s["materials"]:
    m.pop("emission", None)
json.dump(s, open(sys.argv[2], "w"), indent=2)
PY
trap 'rm -rf "$work" scenes/.fire_no_emission.json' EXIT

run() { bench_time "$1" "$2" ${3:+--set "$3"}; }  # scene algorithm [--set value] -> seconds

# The index of a scene's volume material, for --set.
volume_material() {
  python3 -c "import json,sys; print([i for i, m in enumerate(json.load(open(sys.argv[1]))['materials']) if m['type'] == 'volume'][0])" "$1"
}

run scenes/cloud.json raymarch "" >/dev/null
echo "device: $(bench_device "$work/s.json")"
echo "load average at start: $(cut -d' ' -f1-3 /proc/loadavg) on $(nproc) cores"
echo "$resolution; pathtrace: $spp spp, kernel seconds; real-time: median kernel s per frame of $frames frames;" \
  "$reps alternating repetitions after a warm-up of each"
echo
echo "| scene | algorithm | with emission code s (median) | without s (median) | ratio with/without | per-repetition |"
echo "|---|---|---|---|---|---|"
compare() {  # label alg with-scene with-set without-scene without-set
  bench_ab "$1 | $2" 4 3 run "$3 $2 $4" "$5 $2 $6"
}
for alg in pathtrace raymarch lobe; do
  compare "fire: emitting / emission removed" "$alg" scenes/fire.json "" scenes/.fire_no_emission.json ""
done
for scene in scenes/cloud.json scenes/smoke.json scenes/disney_cloud.json; do
  k=$(volume_material "$scene")
  for alg in pathtrace raymarch lobe; do
    compare "$scene: emission code on (Le = 0) / specialised" "$alg" "$scene" \
      "materials[$k].emission={\"color\":[0,0,0]}" "$scene" ""
  done
done
echo
echo "load average at end: $(cut -d' ' -f1-3 /proc/loadavg)"
