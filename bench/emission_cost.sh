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
while [ $# -gt 0 ]; do
  case "$1" in
    --device) device="--device $2"; shift 2 ;;
    --resolution) resolution=$2; shift 2 ;;
    --spp) spp=$2; shift 2 ;;
    --frames) frames=$2; shift 2 ;;
    --reps) reps=$2; shift 2 ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
. bench/bench_common.sh
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

run() {  # scene algorithm extra-set(or "") -> seconds
  local scene=$1 alg=$2 set=$3 extra
  if [ "$alg" = pathtrace ]; then extra="--spp $spp"; else extra="--frames $frames"; fi
  [ -n "$set" ] && extra="$extra --set $set"
  # shellcheck disable=SC2086
  "$narval" render "$scene" -o "$work/out.exr" --algorithm "$alg" --resolution "$resolution" $extra $device \
    --stats-json "$work/s.json" >/dev/null 2>&1
  bench_seconds "$work/s.json" "$alg"
}

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
  local label=$1 alg=$2 ws=$3 wset=$4 os=$5 oset=$6 w=() o=()
  run "$ws" "$alg" "$wset" >/dev/null
  run "$os" "$alg" "$oset" >/dev/null
  for _ in $(seq "$reps"); do
    w+=("$(run "$ws" "$alg" "$wset")")
    o+=("$(run "$os" "$alg" "$oset")")
  done
  python3 - "$label" "$alg" "${w[*]}" "${o[*]}" <<'PY'
import statistics, sys
label, alg = sys.argv[1], sys.argv[2]
w, o = [float(x) for x in sys.argv[3].split()], [float(x) for x in sys.argv[4].split()]
mw, mo = statistics.median(w), statistics.median(o)
per = ", ".join("%.3f" % (a / b) for a, b in zip(w, o))
print(f"| {label} | {alg} | {mw:.4f} | {mo:.4f} | {mw / mo:.3f} | {per} |")
PY
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
