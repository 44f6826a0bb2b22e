#!/usr/bin/env bash
# bench/ms_cache.sh [--frames K] [--resolution WxH] [--ref-spp N] [--scenes "A.json B.json"]
# The ray marcher's multiple scattering (renderer.raymarch.multipleScattering) against the path
# tracer: none, octaves (4), and the path-traced cache at a few resolutions and path counts. Per
# scene: ms per frame (median of K frames after the first), the cache's build ms (apart from the
# frames), mean ΔE76 and JND% against a path-traced reference (REF_SPP spp, the scene's bounces),
# and the reference's own noise floor: a second reference with another seed against the first.
# References are kept in build/realtime_frames (shared with bench/realtime_frames.sh). Not a test.
set -euo pipefail
cd "$(dirname "$0")/.."
narval=build/narval
frames=3
resolution=320x240
ref_spp=256
scenes="scenes/cloud.json scenes/smoke.json scenes/disney_cloud.json scenes/listing_4_1.json"
. bench/bench_common.sh
bench_options "frames resolution ref_spp scenes" "$@"
bench_init
refs=build/realtime_frames
mkdir -p "$refs"

# ref SCENE SEED: the reference's path (bench_reference: rendered unless it is there).
ref() {
  local out
  out="$refs/ref-$(basename "$1" .json)-$resolution-${ref_spp}spp$([ "$2" = 0 ] || echo "-seed$2").exr"
  bench_reference "$out" "$1" --spp "$ref_spp" --resolution "$resolution" --seed "$2"
  echo "$out"
}
delta() {  # REF TEST -> "mean ΔE76 | JND%"
  "$narval" compare "$1" "$2" --json --tonemap none --exposure 0 | python3 -c \
    "import json,sys; d=json.load(sys.stdin); print('%.2f | %.1f%%' % (d['mean_dE76'], d['jnd76_pct']))"
}

echo "device: $("$narval" devices | sed -n 2p)"
echo "command: bench/ms_cache.sh --frames $frames --resolution $resolution --ref-spp $ref_spp"
echo
echo "| scene | ray marcher | ms/frame | cache build ms | mean ΔE76 vs reference | JND% |"
echo "|---|---|---|---|---|---|"
for scene in $scenes; do
  name=$(basename "$scene" .json)
  if ! "$narval" render "$scene" -o "$work/probe.exr" --algorithm raymarch --resolution 8x6 >/dev/null 2>&1; then
    echo "| $name | skipped: the scene does not load (its data absent?) | | | | |"
    continue
  fi
  r0=$(ref "$scene" 0)
  r1=$(ref "$scene" 1)
  echo "| $name | (reference seed 1 against seed 0: the noise floor) | | | $(delta "$r0" "$r1") |"
  for config in "none" "octaves:4" "cache:16:256" "cache:32:256" "cache:16:1024"; do
    IFS=: read -r mode a b <<<"$config"
    sets=(--set "renderer.raymarch.multipleScattering=\"$mode\"")
    [ "$mode" = octaves ] && sets+=(--set "renderer.raymarch.octaves=$a")
    [ "$mode" = cache ] && sets+=(--set "renderer.raymarch.msCache.resolution=$a" --set "renderer.raymarch.msCache.paths=$b")
    "$narval" render "$scene" -o "$work/rm.exr" --algorithm raymarch --resolution "$resolution" --frames "$frames" \
      "${sets[@]}" --stats-json "$work/rm.json" >/dev/null 2>&1
    read -r ms build < <(python3 -c "import json,sys; s=json.load(open(sys.argv[1])); print('%.1f %.0f' % (s['ms_per_frame']['median'], s['ms_cache_ms']))" "$work/rm.json")
    label=$mode
    [ "$mode" = octaves ] && label="octaves $a"
    [ "$mode" = cache ] && label="cache $a cells, $b paths"
    echo "| $name | $label | $ms | $([ "$mode" = cache ] && echo "$build" || echo —) | $(delta "$r0" "$work/rm.exr") |"
  done
done
