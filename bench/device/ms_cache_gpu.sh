#!/usr/bin/env bash
# bench/device/ms_cache_gpu.sh [OUTDIR]: on the GPU machine (after `source bench/device/setup.sh`), the
# multiple-scattering cache against its GPU targets in one pass that fits a short lease; STAGES,
# REF_SPP, HD_SPP, HD_RES, LIMIT and DEADLINE as bench/README.md says. Not a test.
set -u
cd "$(dirname "$0")/../.."
N=$PWD/build/narval
out=${1:-/tmp/ms-cache-gpu}
REF_SPP=${REF_SPP:-131072} HD_SPP=${HD_SPP:-8192} HD_RES=${HD_RES:-1280x720} STAGES=${STAGES:-1 2 3 4}
LIMIT=${LIMIT:-90} DEADLINE=${DEADLINE:-480}
SCALE_PATHS=${SCALE_PATHS:-1}  # a local dry run divides every path count by this
mkdir -p "$out/img" "$out/hd"
t0=$(date +%s)
stamp() { echo "[$(($(date +%s) - t0)) s] $*"; }
run() {
  local left=$((DEADLINE - ($(date +%s) - t0) - 15)) limit=$LIMIT
  [ "$left" -lt "$limit" ] && limit=$left
  [ "$limit" -ge 10 ] || { echo "skipped (deadline): $*"; return; }
  timeout -s INT "$limit" "$N" "$@" 2>&1 | grep -v '^narval: progress' | tail -3
}
sc() { echo "$PWD/scenes/$1.json"; }
view() {  # view TILE PATHS STEPS [FILTER TWICING]: the view cache with the direct light
  echo --algorithm raymarch --set 'renderer.raymarch.multipleScattering="cache"' \
    --set 'renderer.raymarch.msCache.layout="view"' --set renderer.raymarch.msCache.direct=true \
    --set renderer.raymarch.msCache.tile="$1" --set renderer.raymarch.msCache.paths=$((($2 + SCALE_PATHS - 1) / SCALE_PATHS)) \
    --set renderer.raymarch.steps="$3"
  shift 3  # the optional keys are set only where given (not "-"): else the scene's as narval resolves it
  for k in filter filterTwicing; do
    [ $# -gt 0 ] || break
    [ "$1" = - ] || echo --set "renderer.raymarch.msCache.$k=$1"
    shift
  done
}
"$N" devices
for s in cloud smoke disney_cloud disney_cloud_front; do  # fills the program cache
  "$N" render "$(sc $s)" -o "$out/warm.exr" --resolution 64x48 $(view 2 32 30) >/dev/null 2>&1 || echo "warm-up failed: $s"
  "$N" render "$(sc $s)" -o "$out/warm.exr" --resolution 64x48 --spp 4 --storage buffer >/dev/null 2>&1 || echo "warm-up failed: pt $s"
done
stage() { [[ " $STAGES " == *" $1 "* ]]; }
hd_configs=(
  "cloud cloud_t8_p400_s24 8 400 24"
  "cloud cloud_t8_p400_s30 8 400 30"
  "smoke smoke_t8_p400_s30 8 400 30"
  "disney_cloud back_t8_p640_s30 8 640 30"
  "disney_cloud back_t4_p640_s30 4 640 30"
  "disney_cloud_front front_t12_p1216_s30 12 1216 30"
  "disney_cloud_front front_t8_p1216_s30 8 1216 30"
  # With the filter (ms_cache_filter.h), at the 320x240 picks' settings and within a 100 ms build.
  "cloud cloud_t4_p100_f1.5 4 100 30 1.5"
  "cloud cloud_t8_p100_f1 8 100 30 1"
  "smoke smoke_t8_p100_f1 8 100 30 1"
  "disney_cloud back_t4_p160_f1 4 160 30 1"
  "disney_cloud back_t4_p48_f1 4 48 30 1"
  "disney_cloud_front front_t8_p480_f2 8 480 30 2"
  "disney_cloud_front front_t8_p160_f2 8 160 30 2"
  # The back-lit Disney cloud's 320x240 pick, twiced, at 4x the tile, and with fewer paths for a
  # 100 ms build.
  "disney_cloud back_t4_p136_f1.5_twiced 4 136 30 1.5 true"
  "disney_cloud back_t4_p48_f1.5_twiced 4 48 30 1.5 true"
)
stage 1 && stamp "1. real-time picks at $HD_RES"
stage 1 && for c in "${hd_configs[@]}"; do
  set -- $c
  run render "$(sc $1)" -o "$out/hd/$2.exr" --resolution "$HD_RES" --frames 20 $(view "${@:3}") \
    --stats-json "$out/hd/$2.json" | grep -v '^wrote'
done
stage 2 && stamp "2. 320x240 references at $REF_SPP spp"
stage 2 && for s in disney_cloud disney_cloud_front; do
  o=$out/img/ref_$s.exr
  run render "$(sc $s)" -o "$o" --resolution 320x240 --spp $((REF_SPP / 4)) --seed 1 --storage buffer
  cp "$o" "$out/img/ref_${s}_snapshot.exr"
  run render "$(sc $s)" -o "$o" --resolution 320x240 --spp "$REF_SPP" --seed 1 --storage buffer --resume
done
stage 3 && stamp "3. 320x240 caches with many paths"
lo_configs=(
  "disney_cloud back_t2_p8192 2 8192"
  "disney_cloud back_t1_p4096 1 4096"
  "disney_cloud back_t1_p136_f1.5_twiced 1 136 1.5 true"
  "disney_cloud_front front_t2_p480_f2 2 480 2"
  "disney_cloud_front front_t3_p16384 3 16384"
  "disney_cloud_front front_t2_p8192 2 8192"
)
stage 3 && for c in "${lo_configs[@]}"; do
  set -- $c
  run render "$(sc $1)" -o "$out/img/$2.exr" --resolution 320x240 --frames 3 $(view $3 $4 30 "${@:5}") \
    --seed 1 --stats-json "$out/img/$2.json" | grep -v '^wrote'
done
(stage 2 || stage 3) && (cd "$out/img" && tar -cf "$out/images.tar" ./*.exr ./*.json)
stage 4 && stamp "4. $HD_RES references at $HD_SPP spp and the JND of the picks"
stage 4 && for s in cloud smoke disney_cloud disney_cloud_front; do
  o=$out/hd/ref_$s.exr
  run render "$(sc $s)" -o "$o" --resolution "$HD_RES" --spp $((HD_SPP / 4)) --seed 1 --storage buffer
  cp "$o" "$out/hd/ref_${s}_snapshot.exr"
  run render "$(sc $s)" -o "$o" --resolution "$HD_RES" --spp "$HD_SPP" --seed 1 --storage buffer --resume
  for c in "${hd_configs[@]}"; do
    set -- $c
    [ "$1" = "$s" ] || continue
    [ -f "$o" ] && [ -f "$out/hd/$2.exr" ] || continue
    echo "$2: $("$N" compare "$o" "$out/hd/$2.exr" --reference-snapshot "$out/hd/ref_${s}_snapshot.exr" 2>&1 |
      grep -E 'dE76|noise-free' | tr -s ' \n' ' ')"
  done
done
stamp done
python3 - "$out/hd" <<'PY'
import glob, json, os, sys
print("| run | ms_cache_ms | median ms/frame | wall ms/frame |\n|---|---|---|---|")
for f in sorted(glob.glob(os.path.join(sys.argv[1], "*.json"))):
    j = json.load(open(f))
    m = j["ms_per_frame"]
    print(f"| {os.path.basename(f)[:-5]} | {j['ms_cache_ms']:.1f} | {m['median']:.2f} | {m['wall']['median']:.2f} |")
PY
